"""Seeing through f_p, the robot decides on its belief: the simulator's poses reach no decision,
and an episode ends on what the robot senses."""

import pytest

from hsgplan.agents.registry import make_agent
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.parameters import PickParams
from hsgplan.evaluation.observers import make_observer
from hsgplan.sim.env import KitchenStorageEnv, ResetOptions
from hsgplan.sim.outcome import Status

GOAL = parse_goal("On(butter, shelf_a) & On(tomato_soup, shelf_b)", world=KITCHEN)
SEED = 3


@pytest.mark.slow
# the second agent tries each action in its model (a pick run there and taken back)
@pytest.mark.parametrize("agent_name", ["learned", "regression-ahead-checked+gnn-checked"])
def test_moving_the_true_objects_after_a_look_changes_neither_belief_nor_decision(agent_name):
    env = KitchenStorageEnv(observer=make_observer("rgb"), world=KITCHEN)
    try:
        _, info = env.reset(seed=SEED, options=ResetOptions(GOAL))
        obs = info["observation"]

        def decide():
            agent = make_agent(agent_name)
            agent.reset(GOAL, SEED)
            return agent.decide(obs.scene_graph, obs.symbols.state, GOAL, feasible=env.lookahead)

        first = decide()
        believed = env.world.scene.poses()
        for name in env.scene.objects:  # the truth changes behind the robot's back
            env.scene.park(name)
        second = decide()
        assert (second.subgoal, second.action, second.params) == (
            first.subgoal,
            first.action,
            first.params,
        )
        after = env.world.scene.poses()
        assert all(after[n].distance(p) < 1e-9 for n, p in believed.items())
        # acting on it meets the truth: the fingers close where nothing is any more
        assert isinstance(first.params, PickParams)
        _, reward, terminated, _, info = env.step(first.params)
        assert info["outcome"].status is Status.DROPPED
        assert (reward, terminated, info["goal_truly_holds"]) == (0.0, False, False)
    finally:
        env.close()
