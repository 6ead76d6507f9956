"""Property tests of the goal parser: any text is a goal or one refusal, and printed goals read
back as themselves."""

from hypothesis import given, settings
from hypothesis import strategies as st

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.symbolic.generator import random_goals

PIECES = st.sampled_from(
    [
        "On(",
        "In(",
        "InGrasp(",
        "Clear(",
        "not ",
        "!",
        "cherries",
        "butter",
        "shelf_a",
        "popcorn",
        "open_space",
        ", ",
        ")",
        " & ",
        ";",
        "\n",
        " ",
        "(",
        "x",
    ]
)


@settings(max_examples=300, deadline=None)
@given(st.lists(PIECES, max_size=14).map("".join) | st.text(max_size=60))
def test_any_text_is_a_goal_or_one_line_of_refusal(text):
    try:
        goal = parse_goal(text, world=KITCHEN)
    except InvalidInputError as e:
        assert str(e) and "\n" not in str(e)
    else:
        assert goal.literals and parse_goal(str(goal), world=KITCHEN) == goal


@settings(max_examples=50, deadline=None)
@given(st.integers(2, 12), st.integers(0, 10_000))
def test_generated_goals_print_and_parse_back(size, seed):
    for goal in random_goals(size, 2, seed, world=KITCHEN):
        assert parse_goal(str(goal), world=KITCHEN) == goal
        assert parse_goal(str(goal).replace(" & ", "\n"), world=KITCHEN) == goal
