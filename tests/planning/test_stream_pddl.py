"""The PDDLStream-level domain: Fast Downward parses and solves its problems, plans through
its derived predicates (on, clear, unsafepose), and finds none where the streams certified
too little."""

import pytest

from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.planning.fast_downward import NoPlanError, solve_pddl
from hsgplan.symbolic.stream_pddl import DOMAIN, STREAM_SEARCH, goal_text, problem_text

SURFACES = ["open_space", "prepush_a", "prepush_b", "shelf_a", "shelf_b"]


def _problem(goal: str, drop=(), extra=()) -> str:
    """Butter and cherries on the open space; a pose for cherries on shelf A, for butter on
    shelf B, on cherries' shelf pose and on cherries where they stand, each with kinematics."""
    init = [
        ("handempty",),
        ("atpose", "butter", "pb0"),
        ("atpose", "cherries", "pc0"),
        ("supported", "butter", "pb0", "open_space"),
        ("supported", "cherries", "pc0", "open_space"),
        ("supported", "cherries", "pc1", "shelf_a"),
        ("stacked", "butter", "pb1", "cherries", "pc1"),
        ("stacked", "butter", "pb2", "cherries", "pc0"),
        ("grasp", "butter", "gb"),
        ("grasp", "cherries", "gc"),
        ("kin", "butter", "pb0", "gb", "q0"),
        ("kin", "cherries", "pc0", "gc", "q1"),
        ("kin", "cherries", "pc1", "gc", "q2"),
        ("kin", "butter", "pb1", "gb", "q3"),
        ("kin", "butter", "pb2", "gb", "q4"),
        ("supported", "butter", "pb3", "shelf_b"),
        ("kin", "butter", "pb3", "gb", "q5"),
        *extra,
    ]
    for p in ("pb0", "pb1", "pb2", "pb3"):
        init.append(("pose", "butter", p))
    for p in ("pc0", "pc1"):
        init.append(("pose", "cherries", p))
    objects = {
        "obj": ["butter", "cherries"],
        "surface": SURFACES,
        "pose": ["pb0", "pb1", "pb2", "pb3", "pc0", "pc1"],
        "grasp": ["gb", "gc"],
        "conf": [f"q{i}" for i in range(6)],
        "push": [],
    }
    return problem_text(
        objects, [f for f in init if f not in drop], parse_goal(goal, world=KITCHEN)
    )


def _solve(problem: str) -> list[tuple[str, ...]]:
    return [(name, *args) for name, args in solve_pddl(DOMAIN, problem, STREAM_SEARCH).steps]


def test_fast_downward_solves_a_two_object_stack_through_poses():
    plan = _solve(_problem("On(cherries, shelf_a) & On(butter, cherries)"))
    assert plan == [
        ("pick", "cherries", "pc0", "gc", "q1"),
        ("place", "cherries", "pc1", "shelf_a", "gc", "q2"),
        ("pick", "butter", "pb0", "gb", "q0"),
        ("stack", "butter", "pb1", "cherries", "pc1", "gb", "q3"),
    ]


def test_a_covered_object_is_not_clear_and_a_held_one_is_in_grasp():
    # butter goes onto cherries where they stand: then cherries are no longer clear
    plan = _solve(_problem("On(butter, cherries) & not Clear(cherries)"))
    assert plan[-1][:2] == ("stack", "butter")
    assert _solve(_problem("InGrasp(butter)")) == [("pick", "butter", "pb0", "gb", "q0")]


def test_a_pose_that_collides_with_a_standing_object_is_not_placed_on():
    # cherries' shelf pose collides with where butter stands: butter goes elsewhere first
    extra = [
        ("collide", "cherries", "pc1", "butter", "pb0"),
        ("collide", "butter", "pb0", "cherries", "pc1"),
    ]
    plan = _solve(_problem("On(cherries, shelf_a)", extra=extra))
    assert [s[:3] for s in plan] == [
        ("pick", "butter", "pb0"),
        ("place", "butter", "pb3"),
        ("pick", "cherries", "pc0"),
        ("place", "cherries", "pc1"),
    ]
    assert _solve(_problem("On(cherries, shelf_a)")) == [
        ("pick", "cherries", "pc0", "gc", "q1"),
        ("place", "cherries", "pc1", "shelf_a", "gc", "q2"),
    ]


def test_no_plan_where_no_kinematics_was_certified():
    with pytest.raises(NoPlanError):
        _solve(_problem("On(cherries, shelf_a)", drop=[("kin", "cherries", "pc1", "gc", "q2")]))


def test_goal_literals_become_derived_atoms():
    goal = parse_goal("In(tomato_soup, shelf_a) & not On(butter, cherries)", world=KITCHEN)
    assert sorted(goal_text(lit) for lit in goal.literals) == [
        "(in tomato_soup shelf_a)",
        "(not (on butter cherries))",
    ]
