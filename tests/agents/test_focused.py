"""PDDLStream's focused algorithm: optimistic outputs stand for unevaluated streams, only the
streams a plan uses are evaluated, and a returned plan names only certified objects."""

import math

import numpy as np

from hsgplan.agents.focused import (
    FOCUSED_GOAL_DIRECTED,
    FocusedConfig,
    FocusedPlanner,
    _evaluate,
    _optimistic,
)
from hsgplan.agents.registry import SEARCH_BASELINES, make_agent
from hsgplan.agents.stream import StreamAgent
from hsgplan.agents.stream_problem import aim, initial_problem
from hsgplan.domain.actions import Pick, Place, Push
from hsgplan.domain.goals import Goal, parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.evaluation.episode import run_episode
from hsgplan.sim.env import KitchenStorageEnv, ResetOptions

GOAL = parse_goal(
    "On(cherries, shelf_a) & On(butter, cherries) & In(tomato_soup, shelf_a)", world=KITCHEN
)


def _problem(goal, seed=4, goal_stacks=False):
    env = KitchenStorageEnv(world=KITCHEN)
    _, info = env.reset(seed=seed, options=ResetOptions(goal))
    obs = info["observation"]
    env.close()
    prob = initial_problem(obs.scene_graph, obs.symbols.state, np.random.default_rng(0))
    aim(prob, goal, goal_stacks)
    for o in obs.symbols.state.objects:
        prob.grasps.setdefault(o, f"g_{o}")
    return prob, obs.symbols.state


class _Robot:
    """Kinematics that certify every pose but those of `refused`; pushes never found."""

    def __init__(self, refused=()):
        self.refused = set(refused)
        self.asked = []

    def kin(self, pose):
        self.asked.append(pose.obj)
        return None if pose.obj in self.refused else (0.0,) * 7

    def pushes(self, start, shelf):
        return iter(())


def test_complexity_bounds_the_optimistic_objects():
    prob, state = _problem(GOAL)
    assert _optimistic(prob, state, 0, set(), FocusedConfig()).facts == []
    one = _optimistic(prob, state, 1, set(), FocusedConfig())
    two = _optimistic(prob, state, 2, set(), FocusedConfig())
    assert max(one.complexity.values()) == 1 and max(two.complexity.values()) == 2
    assert len(two.facts) > len(one.facts)
    # at 1: a kin for every observed pose, a place pose per object and surface, no kin on those
    kins = [f for f in one.facts if f[0] == "kin"]
    assert {f[2] for f in kins} == set(prob.poses)
    # optimistic poses collide with nothing and are not yet anywhere on the surface
    assert not any(f[0] == "collide" for f in two.facts)
    assert all(math.isnan(v.x) for v in two.poses.values())


def test_goal_directed_streams_offer_fewer_optimistic_objects():
    general, state = _problem(GOAL)
    directed, _ = _problem(GOAL, goal_stacks=True)
    many = _optimistic(general, state, 2, set(), FocusedConfig())
    few = _optimistic(directed, state, 2, set(), FOCUSED_GOAL_DIRECTED)
    assert len(few.maker) < len(many.maker)
    stacks = {i[1:] for i in few.maker.values() if i[0] == "stack"}
    assert {o for o, _ in stacks} == {"butter"}  # only the goal's On(butter, cherries)


def test_a_disabled_sampler_offers_no_optimistic_output():
    prob, state = _problem(GOAL)
    off = {("place", "cherries", s) for s in ("shelf_a", "shelf_b", "open_space")}
    opt = _optimistic(prob, state, 1, off, FocusedConfig())
    offered = {i for i in opt.maker.values() if i[0] == "place"}
    assert not offered & off and ("place", "cherries", "prepush_a") in offered


def test_evaluates_only_the_stream_plan_binding_its_inputs():
    prob, state = _problem(GOAL)
    opt = _optimistic(prob, state, 2, set(), FocusedConfig())
    place = next(n for n, i in opt.maker.items() if i == ("place", "cherries", "shelf_a"))
    kin = next(n for n, i in opt.maker.items() if i == ("kin", place))
    robot = _Robot()
    before = len(prob.poses)
    sampled = _evaluate(prob, opt, {kin}, robot, frozenset(), set(), {})
    # the kin's input, an optimistic pose, was sampled first, then kin ran on the sampled pose
    assert sampled == {("place", "cherries", "shelf_a")}
    assert len(prob.poses) == before + 1 and robot.asked == ["cherries"]
    new = list(prob.poses)[-1]
    assert prob.poses[new].support == "shelf_a" and not math.isnan(prob.poses[new].x)
    assert any(f[0] == "kin" and f[2] == new for f in prob.facts)


def test_a_failed_stream_certifies_nothing_and_its_dependants_wait():
    prob, state = _problem(GOAL)
    opt = _optimistic(prob, state, 3, set(), FocusedConfig())
    place = next(n for n, i in opt.maker.items() if i == ("place", "cherries", "shelf_a"))
    kin = next(n for n, i in opt.maker.items() if i == ("kin", place))
    stack = next(n for n, i in opt.maker.items() if i == ("stack", "butter", place))
    on_top = next(n for n, i in opt.maker.items() if i == ("kin", stack))
    robot = _Robot(refused={"cherries"})
    _evaluate(prob, opt, {kin, on_top}, robot, frozenset(), set(), {})
    facts = list(prob.facts)
    assert not any(f[0] == "kin" and f[1] == "cherries" for f in facts)
    assert any(f[0] == "stacked" and f[1] == "butter" for f in facts)  # stack-pose certified
    assert "butter" in robot.asked  # and its kin, bound to the sampled pose below


def test_plans_and_acts_a_three_object_goal_with_only_certified_objects():
    env = KitchenStorageEnv(world=KITCHEN)
    _, info = env.reset(seed=4, options=ResetOptions(GOAL))
    obs = info["observation"]
    agent = StreamAgent(FocusedPlanner(), "stream-focused")
    agent.reset(GOAL, 4)
    d = agent.decide(obs.scene_graph, obs.symbols.state, GOAL, env.lookahead)
    actions = [d.action] + [s.action for s in agent._queue]
    assert len(actions) == 7 and d.task_seconds > 0
    assert {type(a) for a in actions} == {Pick, Place, Push}
    env.close()
    record = run_episode(
        KitchenStorageEnv(world=KITCHEN), make_agent("stream-focused-goal"), GOAL, seed=4
    )
    assert record.success, record.steps


def test_a_goal_that_holds_needs_no_stream():
    env = KitchenStorageEnv(world=KITCHEN)
    _, info = env.reset(seed=4, options=ResetOptions(GOAL))
    obs = info["observation"]
    env.close()
    holds = Goal(frozenset({obs.symbols.state.location("butter")}), world=KITCHEN)
    found = FocusedPlanner().plan(obs.scene_graph, obs.symbols.state, holds, world=None)
    assert found.steps == () and found.levels == 0  # no world asked: no stream evaluated


def test_is_a_table2_baseline():
    assert {"stream-focused", "stream-focused-goal"} <= set(SEARCH_BASELINES)
    assert make_agent("stream-focused").name == "stream-focused"
