"""Our loop part by part (`planner.Loop`), each part switched off alone, over the shipped
networks (`checkpoints/task`, fixed weights): what the task ladder's rungs measure."""

import random

import pytest

from hsgplan.agents.registry import TASK_PLANNERS
from hsgplan.domain.actions import Pick
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.predicates import on
from hsgplan.domain.recovery import RecoveryRules
from hsgplan.paths import TASK_CHECKPOINT
from hsgplan.planning.regression.planner import OUR_LOOP, Loop, RegressionPlanner
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.symbolic.generator import random_state
from hsgplan.symbolic.transition import apply, why_not

STACK = "On(cherries, shelf_a) & On(butter, cherries)"


def _planner(loop: Loop, seed: int = 0) -> RegressionPlanner:
    return RegressionPlanner(TASK_CHECKPOINT, seed=seed, rules=RecoveryRules.none(), loop=loop)


@pytest.mark.parametrize(
    "name,loop",
    [
        ("regression-bfs", Loop(waits=False, holds=False, keeps_chain=False)),
        ("regression-bfs-wait", Loop(holds=False, keeps_chain=False)),
        ("regression-bfs-wait-holds", Loop(keeps_chain=False)),
        ("regression", OUR_LOOP),
    ],
)
def test_each_rung_adds_one_part_of_the_loop(name, loop):
    planner = TASK_PLANNERS[name](TASK_CHECKPOINT, RecoveryRules.none())
    assert planner.loop == loop and planner.name == name


def test_a_kept_chain_is_followed_without_asking_the_networks_again():
    goal = parse_goal(STACK, world=KITCHEN)
    asked = {}
    for loop in (OUR_LOOP, Loop(keeps_chain=False)):
        planner, calls = _planner(loop), []
        ask = planner._preimages
        planner._preimages = lambda state, nodes, ask=ask, calls=calls: (
            calls.append(1) or ask(state, nodes)
        )
        state = random_state(goal.objects, random.Random(0), world=KITCHEN)
        counts = []
        while not goal.satisfied_by(state) and len(counts) < 12:
            before = len(calls)
            decision = planner.next_action(state, goal)
            counts.append(len(calls) - before)
            if why_not(state, decision.action) is None:
                state = apply(state, decision.action)
        assert goal.satisfied_by(state), loop
        asked[loop.keeps_chain] = counts
    assert 0 in asked[True]  # a step up the chain taken without a call
    assert 0 not in asked[False]  # every decision regressed from the goal


def test_a_literal_whose_preimage_holds_is_reached_only_with_the_part_on():
    # f_reach made to say "out of reach" everywhere: only a preimage that holds finds an action
    goal = parse_goal("On(butter, shelf_a) & On(cherries, shelf_b)", world=KITCHEN)
    state = SymbolicSceneGraph.from_literals(
        ["butter", "cherries"],
        [on("butter", "open_space"), on("cherries", "open_space")],
        world=KITCHEN,
    )
    for loop, found in ((Loop(keeps_chain=False), True), (Loop(holds=False), False)):
        planner = _planner(loop)
        planner.reach_scores = lambda state, lits: [0.0] * len(lits)
        decision = planner.next_action(state, goal)
        assert (decision.action is not None) == found, (loop, decision)


def test_a_stack_top_waits_for_its_base_only_with_the_part_on():
    goal = parse_goal(STACK, world=KITCHEN)
    state = SymbolicSceneGraph.from_literals(
        ["cherries", "butter"],
        [on("cherries", "open_space"), on("butter", "open_space")],
        world=KITCHEN,
    )
    firsts = {}
    for waits in (True, False):
        loop = Loop(waits=waits, keeps_chain=False)
        firsts[waits] = {_planner(loop, s).next_action(state, goal).action for s in range(12)}
    assert firsts[True] == {Pick("cherries")}
    assert Pick("butter") in firsts[False]
