"""Fast Downward and the transition model must agree: every plan replays step by step."""

import random

import pytest

from hsgplan.domain.actions import Place
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.predicates import inside, on
from hsgplan.planning.fast_downward import FastDownwardPlanner, NoPlanError
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.symbolic.generator import random_goals, random_state
from hsgplan.symbolic.pddl import to_pddl_text
from hsgplan.symbolic.transition import apply, why_not


def replay(plan, start, goal):
    state = start
    for action in plan.actions:
        assert why_not(state, action) is None, f"{action} in {state}"
        state = apply(state, action)
    assert goal.satisfied_by(state)


# 12 goals a size: the suite's budget (100 a size hold too, measured outside the suite).
@pytest.mark.slow
@pytest.mark.parametrize("n", [2, 3, 4, 5, 6])
def test_plans_for_random_goals_replay_in_the_transition_model(n):
    planner = FastDownwardPlanner()
    rng = random.Random(f"test-fd-{n}")
    goals = random_goals(n, 12, seed=11, world=KITCHEN)
    starts = [random_state(g.objects, rng, world=KITCHEN) for g in goals]
    for i, goal in enumerate(goals):
        # Half start with everything on the open space, half from a random arrangement.
        start = SymbolicSceneGraph.initial(goal.objects, world=KITCHEN) if i % 2 else starts[i]
        replay(planner.plan(start, goal), start, goal)


@pytest.mark.slow
@pytest.mark.parametrize("n", [7, 9, 12])
def test_generated_goals_up_to_twelve_objects_are_solved(n):
    planner = FastDownwardPlanner(optimal=False)
    rng = random.Random(f"test-fd-large-{n}")
    for goal in random_goals(n, 8, seed=12, world=KITCHEN):
        start = random_state(goal.objects, rng, world=KITCHEN)
        replay(planner.plan(start, goal), start, goal)


@pytest.mark.slow
def test_optimal_plans_are_never_longer():
    rng = random.Random(0)
    for goal in random_goals(4, 6, seed=5, world=KITCHEN):
        start = random_state(goal.objects, rng, world=KITCHEN)
        best = FastDownwardPlanner(optimal=True).plan(start, goal)
        fast = FastDownwardPlanner(optimal=False).plan(start, goal)
        assert len(best) <= len(fast)


def test_known_plan():
    goal = parse_goal("On(butter, cherries) & In(tomato_soup, shelf_a)", world=KITCHEN)
    start = SymbolicSceneGraph.initial(goal.objects, world=KITCHEN)
    plan = FastDownwardPlanner(optimal=True).plan(start, goal)
    assert len(plan) == 5  # pick, place; pick, place on prepush_a, push
    assert [str(a) for a in plan.actions if "tomato_soup" in str(a)] == [
        "pick(tomato_soup)",
        "place(tomato_soup, prepush_a)",
        "push(tomato_soup, shelf_a)",
    ]


def test_banned_actions_are_left_out_of_the_plan():
    # butter must go somewhere before cream_cheese can be picked: banning where it went gives
    # a plan that puts it elsewhere
    start = SymbolicSceneGraph.from_literals(
        ["cream_cheese", "butter"],
        [on("cream_cheese", "open_space"), on("butter", "cream_cheese")],
        world=KITCHEN,
    )
    goal = parse_goal("On(cream_cheese, shelf_b)", world=KITCHEN)
    planner = FastDownwardPlanner(optimal=True)
    first = planner.plan(start, goal)
    away = next(a for a in first.actions if isinstance(a, Place) and a.obj == "butter")
    second = planner.plan(start, goal, banned=[away])
    assert away not in second.actions
    assert any(isinstance(a, Place) and a.obj == "butter" for a in second.actions)
    replay(second, start, goal)
    # no plan reaches the goal without the action it names
    with pytest.raises(NoPlanError, match="no sequence"):
        planner.plan(start, goal, banned=[Place("cream_cheese", "shelf_b")])


def test_goal_already_true_needs_no_plan():
    start = SymbolicSceneGraph.initial(["butter", "cherries"], world=KITCHEN)
    plan = FastDownwardPlanner().plan(start, parse_goal("On(butter, open_space)", world=KITCHEN))
    assert len(plan) == 0 and plan.states == (start,)


def test_unreachable_goal_is_reported():
    # An object inside a shelf can never come out again.
    start = SymbolicSceneGraph.from_literals(
        ["cherries", "butter"],
        [inside("cherries", "shelf_a"), on("butter", "open_space")],
        world=KITCHEN,
    )
    with pytest.raises(NoPlanError, match="no sequence"):
        FastDownwardPlanner().plan(start, parse_goal("On(cherries, shelf_b)", world=KITCHEN))


def test_pddl_text_names_the_domain_actions():
    goal = parse_goal("On(butter, cherries)", world=KITCHEN)
    domain, problem = to_pddl_text(SymbolicSceneGraph.initial(goal.objects, world=KITCHEN), goal)
    for name in (
        "pick_from_surface",
        "pick_from_object",
        "place_on_surface",
        "place_on_object",
        "push",
    ):
        assert f"(:action {name}" in domain
    assert "(on butter cherries)" in problem


def test_the_oracle_plans_around_an_action_that_left_its_state_and_gives_it_up_at_a_limit():
    from collections import Counter

    from hsgplan.planning.fast_downward import TAKEN_LIMIT, FastDownwardTaskPlanner

    goal = parse_goal("On(cherries, shelf_a) & On(butter, shelf_b)", world=KITCHEN)
    start = SymbolicSceneGraph.initial(goal.objects, world=KITCHEN)
    oracle = FastDownwardTaskPlanner()
    oracle.reset(goal, 0)
    named = []
    for _ in range(20):  # every action named from `start` fails: the state never changes
        decision = oracle.next_action(start, goal)
        if decision.action is None:
            break
        named.append(decision.action)
    assert decision.action is None and "no plan" in decision.note
    assert max(Counter(named).values()) == TAKEN_LIMIT


def test_back_in_a_state_the_oracle_takes_a_plan_without_what_it_named_there_first():
    from hsgplan.domain.actions import Pick
    from hsgplan.planning.fast_downward import FastDownwardTaskPlanner, Plan

    goal = parse_goal("On(cherries, shelf_a) & On(butter, shelf_b)", world=KITCHEN)
    start = SymbolicSceneGraph.initial(goal.objects, world=KITCHEN)
    first, other = Pick("cherries"), Pick("butter")

    class TwoPlans:  # a plan through `first` unless it is banned, else one through `other`
        def plan(self, state, goal, banned=frozenset()):
            action = other if first in banned else first
            return Plan((action,), (state, apply(state, action)), 0.0, "stub")

    oracle = FastDownwardTaskPlanner(planner=TwoPlans())
    oracle.reset(goal, 0)
    assert oracle.next_action(start, goal).action == first
    assert oracle.next_action(start, goal).action == other  # `first` left the state as it was
