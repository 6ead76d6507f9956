"""A check by outcome passes a primitive only where it plans and, run in a trial of the model,
reaches its effect; what a trial found is not run again in the same scene. A tiny fake model
stands for the robot's."""

from contextlib import contextmanager
from types import SimpleNamespace

from hsgplan.agents.hierarchical import HierarchicalAgent
from hsgplan.agents.outcomes import OutcomeChecks
from hsgplan.domain.actions import Place
from hsgplan.domain.parameters import PlaceParams
from hsgplan.sim.outcome import Outcome, Status
from tests.agents.test_hierarchical import SG, Motion, Planner

TIPS = PlaceParams("butter", "shelf_a", 0, 9)  # plans, and the box tips off the front
HOLDS = PlaceParams("butter", "shelf_a", 5, 5)
STUCK = PlaceParams("butter", "shelf_a", 9, 9)  # no plan


class Model:
    """Dry runs (no plan for STUCK) and trials in which TIPS falls; counts the trial runs."""

    def __init__(self, scene="start"):
        self.scene, self.runs = scene, []

    def __call__(self, params) -> bool:
        return params != STUCK

    @contextmanager
    def trial(self):
        def run(params):
            self.runs.append(params)
            ok = params != TIPS
            return Outcome(Status.SUCCESS if ok else Status.EFFECT_NOT_REACHED, "", 0.0)

        yield SimpleNamespace(run=run, scene_graph=lambda: self.scene)


def test_a_primitive_passes_only_where_it_plans_and_reaches_its_effect_in_the_model():
    model = Model()
    check = OutcomeChecks(model)
    assert check(HOLDS) and not check(TIPS) and not check(STUCK)
    assert model.runs == [HOLDS, TIPS]  # what does not plan is not run


def test_an_outcome_is_run_once_per_scene():
    model = Model()
    check = OutcomeChecks(model)
    assert not check(TIPS) and not check(TIPS)
    model.scene = "after a neighbour moved"
    check(TIPS)
    assert model.runs == [TIPS, TIPS]


class Ranked(Motion):
    """Proposes the first bin of TIPS, HOLDS that passes the check (a checked generator)."""

    def propose(self, sg, action, following=None, feasible=None):
        self.scene = sg.name
        return next((p for p in (TIPS, HOLDS) if feasible is None or feasible(p)), TIPS)


def test_an_agent_that_tries_outcomes_passes_over_a_bin_that_tips_its_object():
    held = SimpleNamespace(**{**vars(SG), "held": "butter"})
    place = Place("butter", "shelf_a")

    def agent(tries: bool) -> HierarchicalAgent:
        return HierarchicalAgent(
            "fake", Planner([place]), Ranked(), check_actions=True, try_outcomes=tries
        )

    assert agent(False).decide(held, "S", "goal", Model()).params == TIPS
    assert agent(True).decide(held, "S", "goal", Model()).params == HOLDS
