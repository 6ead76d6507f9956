"""Seeing through f_p, the robot decides on its belief (under the ground truth, on its model of
the truth): during a decision the simulated scene is a tripwire (any query of it raises), and
one object moved 3 cm behind the robot's back between a look and a decision leaves the
decision and every dry run as they were. Two kept mutations (an agent that reads the truth;
dry runs sent to the true scene) show the check catching each."""

from dataclasses import dataclass

import numpy as np
import pytest

from hsgplan.agents.registry import make_agent
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.evaluation.observers import make_observer
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.env import KitchenStorageEnv, ResetOptions

GOAL = parse_goal("On(butter, shelf_a) & On(tomato_soup, shelf_b)", world=KITCHEN)
SEED = 3
MOVE = 0.03  # m


class TruthTouched(AssertionError):
    pass


class _Tripwire:
    """Stands for the simulated scene while the robot decides: touching it is the leak."""

    def __getattr__(self, name):
        raise TruthTouched(f"the true scene's '{name}' was read during a decision")


@dataclass(frozen=True)
class Trace:
    """A decision and the dry runs made for it: what each planned (its grasp's joints), or
    that it found no plan."""

    decision: tuple
    dry_runs: tuple


def _decide(env: KitchenStorageEnv, obs, agent_name: str, truth_reader: bool) -> Trace:
    agent = make_agent(agent_name)
    agent.reset(GOAL, SEED)
    truth, env.scene = env.scene, _Tripwire()
    try:
        # the kept mutation `truth_reader`: an agent that looks at the simulator's poses
        sg = env.scene.scene_graph() if truth_reader else obs.scene_graph
        d = agent.decide(sg, obs.symbols.state, GOAL, feasible=env.lookahead)
    finally:
        env.scene = truth
    planned = tuple(
        sorted((str(p), tuple(np.round(plan.q_at, 6))) for p, (plan, _, _) in env._checked.items())
    )
    refused = tuple(sorted(str(p) for p, _ in env._unplannable))
    return Trace((d.subgoal, d.action, d.params), planned + refused)


def blind_to_the_truth(
    env: KitchenStorageEnv, agent_name: str, checks: bool, truth_reader=False
) -> bool:
    """Whether a decision made on the first look is the same, dry runs and all, when one
    object of the scene was moved 3 cm in the simulator after that look, with the simulator
    a tripwire throughout (False where it was touched, or where an agent that `checks` its
    actions made no dry run: nothing would have been tested)."""
    _, info = env.reset(seed=SEED, options=ResetOptions(GOAL))
    obs = info["observation"]
    rng = env.world.scene.rng.bit_generator.state  # dry runs draw from the model's
    try:
        first = _decide(env, obs, agent_name, truth_reader)
        env._checked.clear()
        env._unplannable.clear()
        env.world.scene.rng.bit_generator.state = rng
        moved = first.decision[2].obj  # the object the decision acts on
        p = env.scene.pose(moved)
        env.scene.set_pose(moved, Pose((p.position[0] - MOVE, *p.position[1:]), p.orientation))
        second = _decide(env, obs, agent_name, truth_reader)
    except TruthTouched:
        return False
    return second == first and (first.dry_runs or not checks)


@pytest.fixture
def env():
    env = KitchenStorageEnv(observer=make_observer("rgb"), world=KITCHEN)
    yield env
    env.close()


# the second agent checks each action in its model (dry runs, and a pick run there and taken
# back); the first checks none
CHECKING = "regression-ahead-checked+gnn-checked"


@pytest.mark.slow
@pytest.mark.parametrize(("agent_name", "checks"), [("learned", False), (CHECKING, True)])
def test_a_decision_reads_the_belief_alone(env, agent_name, checks):
    assert blind_to_the_truth(env, agent_name, checks)


@pytest.mark.slow
def test_the_check_catches_an_agent_that_reads_the_truth(env):
    assert not blind_to_the_truth(env, "learned", False, truth_reader=True)


@pytest.mark.slow
def test_the_check_catches_dry_runs_made_in_the_true_scene(env, monkeypatch):
    monkeypatch.setattr(KitchenStorageEnv, "_planning_scene", lambda self: self.scene)
    assert not blind_to_the_truth(env, CHECKING, True)


@pytest.mark.slow
def test_dry_runs_and_trials_under_the_ground_truth_run_in_a_model_of_their_own():
    """Under the ground truth the robot sees the simulator's poses, yet plans, dry-runs and
    tries in its own model of them: the simulated scene is not touched while it decides."""
    env = KitchenStorageEnv(observer=make_observer("gt"), world=KITCHEN)
    try:
        assert blind_to_the_truth(env, CHECKING, True)
    finally:
        env.close()
