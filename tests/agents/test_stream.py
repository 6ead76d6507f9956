"""The PDDLStream-style baseline: its streams' collision test, a goal solved in the simulated
world, its plan followed and what failed left out, and its place in Table 2."""

import numpy as np
import pytest
from typer.testing import CliRunner

from hsgplan.agents.incremental import (
    GOAL_DIRECTED,
    IncrementalConfig,
    IncrementalPlanner,
)
from hsgplan.agents.registry import make_agent
from hsgplan.agents.stream import StreamAgent, expected_after, scene_key
from hsgplan.agents.stream_problem import aim, initial_problem
from hsgplan.agents.streams import collides, stack_pose, surface_pose
from hsgplan.benchmarks.timing import tables, timing_agents
from hsgplan.cli import app
from hsgplan.domain.actions import Pick, Place, Push
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.parameters import PickParams, PushParams
from hsgplan.domain.predicates import in_grasp, on
from hsgplan.evaluation.episode import run_episode
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.sim.env import KitchenStorageEnv, ResetOptions
from hsgplan.sim.outcome import Outcome, Status


def test_collision_test_keeps_towers_and_flags_crowding():
    can = surface_pose("cherries", "shelf_a", (2, 5), KITCHEN)
    beside = surface_pose("tomato_soup", "shelf_a", (2, 6), KITCHEN)  # the next bin: 2.4 cm apart
    far = surface_pose("tomato_soup", "shelf_a", (8, 0), KITCHEN)
    assert collides(can, beside) and collides(beside, can)
    assert not collides(can, far)
    on_can = stack_pose("butter", can)
    on_butter = stack_pose("tomato_soup", on_can)
    assert not collides(on_can, can) and not collides(on_butter, can)  # a tower stands
    # the hand taking a flat box would sweep into a tall can standing past its narrow side
    box = surface_pose("butter", "open_space", (5, 5), KITCHEN)
    tall = surface_pose("alphabet_soup", "open_space", (8, 5), KITCHEN)  # 11 cm away along x
    assert collides(box, tall) and not collides(
        box, surface_pose("cherries", "shelf_b", (0, 0), KITCHEN)
    )
    assert (
        stack_pose("butter", surface_pose("popcorn", "shelf_a", (5, 5), KITCHEN)) is None
    )  # too narrow


def test_expected_state_moves_only_the_acting_object():
    state = SymbolicSceneGraph.from_literals(
        ("butter", "cherries"),
        [on("butter", "open_space"), on("cherries", "shelf_a")],
        world=KITCHEN,
    )
    held = expected_after(state, Pick("butter"))
    assert held.holds(in_grasp("butter")) and held.holds(on("cherries", "shelf_a"))
    stacked = expected_after(held, Place("butter", "cherries"))
    assert stacked.holds(on("butter", "cherries"))


def test_solves_a_three_object_goal():
    goal = parse_goal(
        "On(cherries, shelf_a) & On(butter, cherries) & In(tomato_soup, shelf_a)", world=KITCHEN
    )
    record = run_episode(KitchenStorageEnv(world=KITCHEN), StreamAgent(), goal, seed=4)
    assert record.success, record.steps
    assert any(s.action.startswith("push(tomato_soup") for s in record.steps)
    # planned once before the first step, streams and Fast Downward both timed
    assert record.steps[0].task_seconds > 0 and record.steps[0].motion_seconds > 0
    if all(s.status == "success" for s in record.steps):
        assert all(s.task_seconds == 0 for s in record.steps[1:])


def test_follows_its_plan_and_leaves_out_what_failed_in_that_scene():
    goal = parse_goal("On(butter, shelf_b)", world=KITCHEN)
    env = KitchenStorageEnv(world=KITCHEN)
    _, info = env.reset(seed=5, options=ResetOptions(goal))
    obs = info["observation"]
    agent = StreamAgent(IncrementalPlanner(IncrementalConfig(max_levels=3)))
    agent.reset(goal, 5)
    first = agent.decide(obs.scene_graph, obs.symbols.state, goal, env.lookahead)
    assert first.action == Pick("butter") and first.params == PickParams("butter")
    assert first.task_seconds > 0 and first.motion_seconds > 0
    assert [s.action for s in agent._queue] == [Place("butter", "shelf_b")]
    agent.observe(first.params, Outcome(Status.NO_IK, "", 0.0))
    assert agent._queue == []
    assert agent._failed == {scene_key(obs.scene_graph): {PickParams("butter")}}
    # the only way to the goal starts with that pick: in this scene there is none now
    again = agent.decide(obs.scene_graph, obs.symbols.state, goal, env.lookahead)
    assert again.action is None and "no plan" in again.note
    env.close()


def test_without_the_world_offers_nothing():
    goal = parse_goal("On(butter, shelf_b)", world=KITCHEN)
    env = KitchenStorageEnv(world=KITCHEN)
    _, info = env.reset(seed=3, options=ResetOptions(goal))
    obs = info["observation"]
    d = StreamAgent().decide(obs.scene_graph, obs.symbols.state, goal, env.check)
    assert d.action is None and "scene" in d.note
    env.close()


def test_is_a_registered_agent_and_a_table2_baseline():
    assert isinstance(make_agent("stream"), StreamAgent)
    assert timing_agents("stream") == {"ours": "learned", "stream": "stream"}
    with pytest.raises(InvalidInputError, match="search baseline"):
        timing_agents("wizard")
    row = {"task_s": 2.0, "task_q1": 1.0, "task_q3": 3.0, "success_rate": 1.0}
    row |= {"motion_s": 1.0, "motion_q1": 1.0, "motion_q3": 1.0}
    report = {"by_size": {"3": {"ours": row, "stream": row}}, "search": "stream"}
    report |= {"goals": 1, "seed": 0, "workers": 1}
    table = tables(report)[0]
    assert "stream task s" in table.header and "PDDLStream-style" in table.title


def test_timing_refuses_an_unknown_baseline_in_one_line():
    r = CliRunner().invoke(app, ["bench", "timing", "--search", "wizard"])
    assert r.exit_code == 2
    lines = [line for line in r.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and "'wizard' is not one of" in lines[0]


def test_plans_a_push_from_a_prepush_pose():
    goal = parse_goal("In(tomato_soup, shelf_a)", world=KITCHEN)
    env = KitchenStorageEnv(world=KITCHEN)
    _, info = env.reset(seed=2, options=ResetOptions(goal))
    obs = info["observation"]
    agent = StreamAgent()
    d = agent.decide(obs.scene_graph, obs.symbols.state, goal, env.lookahead)
    assert [d.action] + [s.action for s in agent._queue] == [
        Pick("tomato_soup"),
        Place("tomato_soup", "prepush_a"),
        Push("tomato_soup", "shelf_a"),
    ]
    assert isinstance(agent._queue[-1].params, PushParams)
    env.close()


class _NoRobot:
    """A world whose kinematics and pushes certify nothing: only the poses are looked at."""

    def kin(self, pose):
        return None

    def pushes(self, start, shelf):
        return iter(())


def test_goal_restricted_streams_stack_and_place_only_where_the_goal_leads():
    goal = parse_goal(
        "On(cherries, shelf_a) & On(butter, cherries) & In(tomato_soup, shelf_a)", world=KITCHEN
    )
    env = KitchenStorageEnv(world=KITCHEN)
    _, info = env.reset(seed=4, options=ResetOptions(goal))
    obs = info["observation"]
    env.close()

    def sampled(config):
        prob = initial_problem(obs.scene_graph, obs.symbols.state, np.random.default_rng(0))
        aim(prob, goal, config.goal_stacks)
        for level in (1, 2, 3):
            IncrementalPlanner(config)._evaluate(prob, level, _NoRobot(), frozenset())
        new = [p for p in prob.poses if prob.level[p] > 0]
        values = [prob.poses[p] for p in new]
        places = {(v.obj, v.support) for v in values if v.relation == "supported"}
        under = [(prob.poses[p], prob.poses[prob.below[p]]) for p in new if p in prob.below]
        return {(v.obj, b.obj, b.support) for v, b in under}, places

    stacks, places = sampled(GOAL_DIRECTED)
    assert stacks == {("butter", "cherries", "shelf_a")}  # only on cherries where its goal is
    assert places == {
        ("cherries", "open_space"),
        ("cherries", "shelf_a"),
        ("butter", "open_space"),
        ("tomato_soup", "open_space"),
        ("tomato_soup", "prepush_a"),
    }
    stacks, places = sampled(IncrementalConfig())  # the general streams
    assert {("cherries", "butter"), ("tomato_soup", "butter")} <= {(o, b) for o, b, _ in stacks}
    assert ("butter", "shelf_b") in places and ("butter", "cherries", "open_space") in stacks
