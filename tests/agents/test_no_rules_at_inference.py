"""The learned task planners decide without the hand-written rules: while a planner decides, no
function of the transition model, PDDL, the goal generator, Fast Downward or the feasibility
rules runs (any call, however reached, is caught by a profiler, not only direct imports). The
symbolic loop around the planner is the world and steps the transition model between decisions."""

import random

import pytest

from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.evaluation.task_eval import run_task_episode
from hsgplan.paths import TASK_CHECKPOINT, shipped
from hsgplan.planning.regression.forward import ForwardPlanner
from hsgplan.planning.regression.paper_loop import PaperRegressionPlanner
from hsgplan.planning.regression.planner import RegressionPlanner
from tests.forbidden_calls import rules_forbidden

GOALS = [
    "On(cherries, shelf_a) & On(butter, cherries)",
    "In(tomato_soup, shelf_a) & On(popcorn, shelf_b) & On(cream_cheese, shelf_a)",
    "On(cherries, shelf_b) & On(butter, cherries) & In(alphabet_soup, shelf_a) & "
    "On(popcorn, shelf_a) & In(tomato_soup, shelf_a) & On(cream_cheese, shelf_b)",
]


class Guarded:
    """A planner whose every decision runs under `rules_forbidden`."""

    def __init__(self, planner, calls: list[str]) -> None:
        self.planner, self.calls = planner, calls

    def next_action(self, state, goal):
        with rules_forbidden(self.calls):
            return self.planner.next_action(state, goal)


def test_the_profiler_catches_a_call_into_the_transition_model():
    from hsgplan.symbolic.generator import random_state
    from hsgplan.symbolic.transition import applicable_actions

    calls: list[str] = []
    goal = parse_goal(GOALS[0], world=KITCHEN)
    state = random_state(goal.objects, random.Random(0), world=KITCHEN)
    with rules_forbidden(calls):
        applicable_actions(state)
    assert any("applicable_actions" in c for c in calls)


@pytest.mark.parametrize("kind", ["regression", "regression-ahead", "regression-paper", "forward"])
def test_a_learned_planner_decides_without_the_rules(kind):
    checkpoint = shipped(TASK_CHECKPOINT)
    # the forward planner searches with f_reach at every node: one seed and the shortest goal
    # are its budget (under the profiler its three-object episode alone takes half a minute)
    for text in GOALS if kind != "forward" else GOALS[:1]:
        goal = parse_goal(text, world=KITCHEN)
        for seed in range(2 if kind == "regression" else 1):
            calls: list[str] = []
            if kind == "regression-ahead":
                planner = RegressionPlanner(checkpoint, seed=seed, look_ahead=True)
            elif kind == "regression":
                planner = RegressionPlanner(checkpoint, seed=seed)
            elif kind == "regression-paper":
                planner = PaperRegressionPlanner(checkpoint, seed=seed)
            else:
                planner = ForwardPlanner(checkpoint)
            planner.reset(goal, seed)
            episode = run_task_episode(Guarded(planner, calls), goal, seed, 0)
            assert episode.decision_ms, text  # decisions were made
            assert calls == [], (text, seed, calls[:3])
