"""An agent that checks its actions refuses those that do not plan in its model and asks the
task planner again; one that does not takes the planner's action as it comes. Tiny fakes stand
for the planner, the motion generator and the model of the scene."""

from contextlib import contextmanager
from dataclasses import replace
from types import SimpleNamespace

from hsgplan.agents.hierarchical import REFUSALS, HierarchicalAgent
from hsgplan.domain.actions import Action, Pick, Place, Push
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.parameters import PickParams, PlaceParams, PushParams
from hsgplan.domain.predicates import in_grasp
from hsgplan.domain.recovery import ALL_RULES, RecoveryRules
from hsgplan.planning.base import TaskDecision
from hsgplan.sim.outcome import Outcome, Status

SG = SimpleNamespace(world=KITCHEN, held=None, name="start")
AFTER_PICK = SimpleNamespace(world=KITCHEN, held="cherries", name="after the pick")


class Planner:
    """Names the first of `actions` not refused; a pick is followed by the place in `then`."""

    def __init__(self, actions: list[Action], then: dict[Action, Action] | None = None):
        self.actions, self.then = actions, then or {}
        self.asked: list[frozenset[Action]] = []

    def reset(self, goal, seed):
        pass

    def next_action(self, state, goal, refused=frozenset()):
        self.asked.append(refused)
        for a in self.actions:
            if a not in refused:
                following = self.then.get(a)
                return TaskDecision(a, in_grasp(a.obj), 0.0, following=following)
        return TaskDecision.none("nothing left", 0.0)


class Motion:
    """One parameter choice per action; remembers the scene of its last proposal."""

    name = "fake"

    def __init__(self):
        self.scene = None

    def reset(self, seed):
        pass

    def propose(self, sg, action, following=None, feasible=None):
        self.scene = sg.name
        if isinstance(action, Pick):
            return PickParams(action.obj)
        if isinstance(action, Push):
            return PushParams(action.obj, 0, 0)
        return PlaceParams(action.obj, action.target, 0, 0)

    def observe(self, params, outcome):
        pass


class Model:
    """A dry run (no plan for `unplannable`) and trials whose pick leaves AFTER_PICK; after a
    pick, the places in `blocked_after_pick` do not plan."""

    def __init__(self, unplannable=(), blocked_after_pick=()):
        self.unplannable = set(unplannable)
        self.blocked = set(blocked_after_pick)
        self.in_trial = False
        self.checked: list[object] = []

    def __call__(self, params) -> bool:
        self.checked.append(params)
        return params not in (self.blocked if self.in_trial else self.unplannable)

    @contextmanager
    def trial(self):
        self.in_trial = True
        try:
            yield SimpleNamespace(
                run=lambda params: Outcome(Status.SUCCESS, "", 0.0), scene_graph=lambda: AFTER_PICK
            )
        finally:
            self.in_trial = False


def agent(planner, check: bool) -> HierarchicalAgent:
    return HierarchicalAgent("fake", planner, Motion(), check_actions=check)


def test_without_checks_the_planners_action_is_taken_unchecked():
    model = Model(unplannable={PickParams("cherries")})
    d = agent(Planner([Pick("cherries"), Pick("butter")]), False).decide(SG, None, None, model)
    assert d.params == PickParams("cherries")
    assert model.checked == []


def test_an_action_that_does_not_plan_is_refused_and_the_planner_asked_again():
    planner = Planner([Pick("cherries"), Pick("butter")])
    model = Model(unplannable={PickParams("cherries")})
    d = agent(planner, True).decide(SG, None, None, model)
    assert d.action == Pick("butter") and d.params == PickParams("butter")
    assert planner.asked == [frozenset(), frozenset({Pick("cherries")})]


def test_a_pick_whose_place_does_not_plan_after_it_is_refused():
    place = Place("cherries", "shelf_a")
    planner = Planner([Pick("cherries"), Pick("butter")], then={Pick("cherries"): place})
    model = Model(blocked_after_pick={PlaceParams("cherries", "shelf_a", 0, 0)})
    a = agent(planner, True)
    d = a.decide(SG, None, None, model)
    assert d.action == Pick("butter")
    # the place was proposed in the scene after the pick, and the generator is back in this one
    assert PlaceParams("cherries", "shelf_a", 0, 0) in model.checked
    assert a.motion.scene == "start"


def test_a_pick_whose_place_plans_after_it_is_taken():
    place = Place("cherries", "shelf_a")
    planner = Planner([Pick("cherries"), Pick("butter")], then={Pick("cherries"): place})
    d = agent(planner, True).decide(SG, None, None, Model())
    assert d.action == Pick("cherries")


def test_when_every_action_is_refused_the_first_choice_is_taken_as_without_checks():
    names = ["cherries", "butter", "popcorn"]
    planner = Planner([Pick(n) for n in names])
    model = Model(unplannable={PickParams(n) for n in names})
    d = agent(planner, True).decide(SG, None, None, model)
    assert d.action == Pick("cherries") and d.params == PickParams("cherries")
    assert len(planner.asked) == 4  # the last answer: nothing left


def test_refusals_stop_at_the_budget():
    names = [f"o{k}" for k in range(REFUSALS + 5)]
    planner = Planner([Pick(n) for n in names])
    model = Model(unplannable={PickParams(n) for n in names})
    d = agent(planner, True).decide(SG, None, None, model)
    assert d.action == Pick("o0")
    assert len(planner.asked) == REFUSALS + 1


def checking_agent(planner, rules=ALL_RULES) -> HierarchicalAgent:
    return HierarchicalAgent("fake", planner, Motion(), rules, check_actions=True)


def step(a: HierarchicalAgent, state: str, status: Status = Status.SUCCESS) -> Action:
    """One decision in `state` (the symbolic state stands as a name), its outcome told."""
    d = a.decide(SG, state, "goal", Model())
    a.observe(d.params, Outcome(status, "", 0.0))
    return d.action


def test_an_action_that_succeeded_from_this_very_state_is_refused_there():
    planner = Planner([Pick("cherries"), Pick("butter")])
    a = checking_agent(planner)
    assert step(a, "S") == Pick("cherries")
    assert step(a, "T") == Pick("cherries")  # another state: nothing refused
    assert step(a, "S") == Pick("butter")  # back where it succeeded: the world came back
    assert planner.asked[-1] == frozenset({Pick("cherries")})


def test_an_action_that_failed_there_is_not_refused_as_a_repeat():
    a = checking_agent(Planner([Pick("cherries"), Pick("butter")]))
    assert step(a, "S", Status.NO_PATH) == Pick("cherries")
    assert step(a, "S") == Pick("cherries")


def test_with_nothing_but_repeats_left_the_repeat_is_taken_and_the_rule_switches_off():
    a = checking_agent(Planner([Pick("cherries")]))
    assert [step(a, "S") for _ in range(3)] == [Pick("cherries")] * 3
    planner = Planner([Pick("cherries"), Pick("butter")])
    off = checking_agent(planner, replace(RecoveryRules(), refuse_repeats=False))
    assert [step(off, "S") for _ in range(2)] == [Pick("cherries")] * 2
    assert frozenset({Pick("cherries")}) not in planner.asked
    reset = checking_agent(Planner([Pick("cherries"), Pick("butter")]))
    step(reset, "S")
    reset.reset("goal", 0)  # a new episode remembers nothing
    assert step(reset, "S") == Pick("cherries")
