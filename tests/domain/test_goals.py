import pytest

from hsgplan.domain.errors import InfeasibleError, InvalidInputError, UnknownNameError
from hsgplan.domain.goals import Goal, parse_goal, read_goal_file, write_goal_file
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.predicates import Literal, Predicate, clear, in_grasp, inside, on


def test_separators_and_spacing():
    expected = {on("butter", "cherries"), inside("tomato_soup", "shelf_a"), clear("butter")}
    for text in [
        "On(butter, cherries) & In(tomato_soup, shelf_a) & Clear(butter)",
        "On(butter,cherries);In(tomato_soup,shelf_a);Clear(butter)",
        "On(butter, cherries)\nIn(tomato_soup, shelf_a)\n  Clear(butter)  \n",
        "  On ( butter , cherries ) &In(tomato_soup, shelf_a)& Clear( butter )",
    ]:
        assert parse_goal(text, world=KITCHEN).literals == frozenset(expected)


def test_names_are_case_insensitive_and_may_be_camel_case():
    goal = parse_goal(
        "on(AlphabetSoup, ShelfA) & INGRASP(Cherries_2) & inGrasp(cherries_2)", world=KITCHEN
    )
    assert goal.literals == {on("alphabet_soup", "shelf_a"), in_grasp("cherries_2")}


def test_negation_and_size():
    goal = parse_goal(
        "not On(butter, open_space) & !Clear(cherries) & On(popcorn, shelf_b)", world=KITCHEN
    )
    assert Literal(Predicate.ON, ("butter", "open_space"), positive=False) in goal.literals
    assert Literal(Predicate.CLEAR, ("cherries",), positive=False) in goal.literals
    assert goal.size == 3
    assert goal.objects == ("cherries", "popcorn", "butter")


def test_problem_size_counts_objects_not_fixtures():
    assert parse_goal("On(butter, shelf_a) & On(cherries, butter)", world=KITCHEN).size == 2
    assert parse_goal("In(cherries, shelf_a) & In(cherries_2, shelf_a)", world=KITCHEN).size == 2


def test_text_round_trip():
    text = (
        "On(butter, cherries) & In(tomato_soup, shelf_a) & not Clear(popcorn) "
        "& On(cherries, shelf_b)"
    )
    goal = parse_goal(text, world=KITCHEN)
    assert parse_goal(str(goal), world=KITCHEN) == goal
    assert isinstance(hash(goal), int)


HOSTILE = [
    # syntax
    ("", "empty"),
    ("   \n ; & ", "empty"),
    ("On(butter, cherries) && Clear(butter)", "no literal between '&' and '&'"),
    ("On(cherries, shelf_a) &", "ends with '&'"),
    ("On(cherries, shelf_a) ;\n", "ends with ';'"),
    ("& On(cherries, shelf_a)", "starts with '&'"),
    ("On butter cherries", "not a literal"),
    ("On(butter, cherries", "not a literal"),
    ("On(butter, cherries))", "not a literal"),
    ("On((butter), cherries)", "not a literal"),
    ("On(butter; cherries)", "not a literal"),
    ("On(butter, 'cherries')", "not a name"),
    ("On(butter, cher ries)", "not a name"),
    ("On(butter, 3cherries)", "not a name"),
    ("On(butter, )", "not a name"),
    ("Clear()", "takes 1"),
    ("On(butter)", "takes 2"),
    ("In(cherries, shelf_a, shelf_b)", "takes 2"),
    ("InGrasp(butter, cherries)", "takes 1"),
    ("On(butter, cherries) | Clear(butter)", "not a literal"),
    ("x" * 20_000, "characters long"),
    # unknown names
    ("Under(butter, cherries)", "unknown predicate"),
    ("On(banana, shelf_a)", "unknown name 'banana'"),
    ("On(butter, shelf_c)", "unknown name 'shelf_c'"),
    ("On(cherries_1, shelf_a)", "first cherries"),
    ("On(cherries_13, shelf_a)", "at most 12"),
    # argument kinds
    ("In(cherries, open_space)", "must be a shelf"),
    ("In(cherries, butter)", "must be a shelf"),
    ("On(shelf_a, shelf_b)", "must be a object"),
    ("Clear(shelf_a)", "must be a object"),
    ("InGrasp(open_space)", "must be a object"),
    # contradictions
    ("On(butter, butter)", "itself"),
    ("On(butter, cherries) & On(cherries, butter)", "cycle"),
    ("On(butter, cherries) & On(cherries, tomato_soup) & On(tomato_soup, butter)", "cycle"),
    ("On(butter, shelf_a) & On(butter, shelf_b)", "one place"),
    ("On(cherries, shelf_a) & In(cherries, shelf_a)", "one place"),
    ("InGrasp(butter) & On(butter, shelf_a)", "one place"),
    ("InGrasp(butter) & InGrasp(cherries)", "one object at a time"),
    ("Clear(cherries) & On(butter, cherries)", "rests on"),
    ("Clear(cherries) & InGrasp(cherries)", "held object is not clear"),
    ("Clear(cherries) & In(cherries, shelf_a)", "never clear"),
    ("On(butter, cherries) & not On(butter, cherries)", "both true and false"),
    ("On(butter, cherries) & On(cream_cheese, cherries)", "at most one other"),
    ("InGrasp(cherries) & On(butter, cherries)", "held object carries nothing"),
    # physically impossible
    ("In(popcorn, shelf_a)", "does not fit"),
    ("On(butter, popcorn)", "too narrow"),
    ("In(cherries, shelf_a) & On(butter, cherries)", "inside a shelf"),
    ("On(butter, cherries) & On(cherries, tomato_soup)", "towers hold at most"),
    (
        " & ".join(f"In(cherries{s}, shelf_a)" for s in ("", "_2", "_3", "_4")),
        "interior holds at most 3",
    ),
    (
        " & ".join(
            f"On(cherries{'' if k == 1 else f'_{k}'}, shelf_b)"
            for k in range(1, KITCHEN.surface_capacity["shelf_b"] + 2)
        ),
        f"holds at most {KITCHEN.surface_capacity['shelf_b']}",
    ),
    (
        " & ".join(f"On(butter{'' if k == 1 else f'_{k}'}, prepush_a)" for k in range(1, 4)),
        "holds at most 2",
    ),
    (
        " & ".join(f"Clear(butter{'' if k == 1 else f'_{k}'})" for k in range(1, 13))
        + " & Clear(cherries)",
        "at most 12",
    ),
]


def test_there_are_at_least_thirty_hostile_cases():
    assert len(HOSTILE) >= 30


@pytest.mark.parametrize(("text", "reason"), HOSTILE, ids=[f"h{i}" for i in range(len(HOSTILE))])
def test_hostile_goal_is_refused_with_one_line_naming_the_reason(text, reason):
    with pytest.raises(InvalidInputError) as info:
        parse_goal(text, world=KITCHEN)
    message = str(info.value)
    assert reason in message
    assert "\n" not in message
    assert len(message) < 400


def test_refusals_name_the_offending_literal():
    with pytest.raises(UnknownNameError, match=r"'On\(banana, shelf_a\)'"):
        parse_goal("On(butter, shelf_a) & On(banana, shelf_a)", world=KITCHEN)
    with pytest.raises(
        InfeasibleError, match=r"'On\(butter, shelf_a\)' and 'On\(butter, shelf_b\)'"
    ):
        parse_goal("On(butter, shelf_a) & On(butter, shelf_b)", world=KITCHEN)


def test_unvalidated_parse_keeps_contradictions_for_callers_that_check_later():
    goal = parse_goal("On(butter, shelf_a) & On(butter, shelf_b)", validate=False, world=KITCHEN)
    assert len(goal.literals) == 2


def test_goal_file_round_trip(tmp_path):
    goals = [
        parse_goal("On(butter, shelf_a)", world=KITCHEN),
        parse_goal("In(cherries, shelf_a) & On(popcorn, shelf_b)", world=KITCHEN),
    ]
    path = tmp_path / "goals.txt"
    write_goal_file(path, goals, header="two goals\nfor a test")
    assert path.read_text().startswith("# two goals\n# for a test\n")
    assert read_goal_file(path, world=KITCHEN) == goals


def test_goal_file_errors_carry_the_line_number(tmp_path):
    path = tmp_path / "goals.txt"
    path.write_text("# header\nOn(butter, shelf_a)\n\nOn(butter, butter)\n")
    with pytest.raises(InfeasibleError, match=r"goals.txt:4: "):
        read_goal_file(path, world=KITCHEN)
    with pytest.raises(InvalidInputError, match="does not exist"):
        read_goal_file(tmp_path / "missing.txt", world=KITCHEN)
    (tmp_path / "empty.txt").write_text("# nothing\n")
    with pytest.raises(InvalidInputError, match="holds no goal"):
        read_goal_file(tmp_path / "empty.txt", world=KITCHEN)


def test_goal_is_satisfied_by_state():
    from hsgplan.scene_graph.symbolic import SymbolicSceneGraph

    state = SymbolicSceneGraph.from_literals(
        ["cherries", "butter"], [on("butter", "cherries"), on("cherries", "shelf_a")], world=KITCHEN
    )
    assert parse_goal("On(butter, cherries) & not Clear(cherries)", world=KITCHEN).satisfied_by(
        state
    )
    unmet = Goal(frozenset({clear("cherries"), on("butter", "cherries")}), world=KITCHEN)
    assert not unmet.satisfied_by(state)
    assert unmet.unsatisfied(state) == [clear("cherries")]


def test_a_goal_over_look_alikes_is_read_with_them_swapped_in_every_way():
    goal = parse_goal(
        "On(cherries, shelf_a) & On(cherries_2, butter) & On(popcorn, shelf_b)", world=KITCHEN
    )
    readings = goal.readings()
    assert readings[0] == goal and len(readings) == 2
    swapped = parse_goal(
        "On(cherries_2, shelf_a) & On(cherries, butter) & On(popcorn, shelf_b)", world=KITCHEN
    )
    assert readings[1] == swapped
    assert parse_goal("On(popcorn, shelf_b) & On(cherries, butter)", world=KITCHEN).readings() == [
        parse_goal("On(popcorn, shelf_b) & On(cherries, butter)", world=KITCHEN)
    ]


def test_a_goal_without_some_objects_keeps_the_literals_naming_none_of_them():
    g = parse_goal(
        "On(butter, shelf_b) & On(cherries, butter) & In(tomato_soup, shelf_a)", world=KITCHEN
    )
    assert g.without(("cherries",)).literals == {
        on("butter", "shelf_b"),
        inside("tomato_soup", "shelf_a"),
    }
    assert str(g.without(("butter",))) == "In(tomato_soup, shelf_a)"
    assert g.without(()) == g
    assert g.without(("butter", "tomato_soup")) is None
