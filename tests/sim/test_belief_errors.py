"""What the record says of the belief a step was planned on: how far it had the objects the
step acted on from the simulator's poses."""

import math

import pytest

from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.parameters import PickParams
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.geometry import Pose, rotation_apart
from hsgplan.sim.env import KitchenStorageEnv, ResetOptions
from hsgplan.sim.observer import Seen
from hsgplan.sim.outcome import BELIEF_OFF, BELIEF_TURNED, BeliefError, belief_errors


def test_a_turn_the_shape_cannot_show_is_no_error():
    at = Pose.from_xyz_yaw(0.5, 0.0, 0.02)
    assert rotation_apart(at, Pose.from_xyz_yaw(0.5, 0.0, 0.02, math.pi), False) < 1e-4
    assert rotation_apart(at, Pose.from_xyz_yaw(0.5, 0.0, 0.02, 0.5), False) == pytest.approx(
        math.degrees(0.5)
    )
    assert rotation_apart(at, Pose.from_xyz_yaw(0.5, 0.0, 0.02, 2.0), True) < 1e-4
    tilted = Pose((0.5, 0.0, 0.02), (math.sin(0.2), 0.0, 0.0, math.cos(0.2)))  # 0.4 rad about x
    assert rotation_apart(at, tilted, True) == pytest.approx(math.degrees(0.4))


def test_each_object_both_hold_is_measured_and_the_rest_are_left_out():
    truth = {
        "butter": Pose.from_xyz_yaw(0.5, 0.0, 0.012),
        "cherries": Pose.from_xyz_yaw(0.4, 0.1, 0.029),
    }
    believed = GeometricSceneGraph.from_poses(
        {"butter": Pose.from_xyz_yaw(0.53, 0.0, 0.012, math.radians(30))}, world=KITCHEN
    )
    found = belief_errors(believed, truth, ("butter", "cherries", "shelf_a"), KITCHEN)
    assert [e.obj for e in found] == ["butter"]  # cherries unseen, shelf_a no object
    assert found[0].off == pytest.approx(0.03, abs=1e-4)
    assert found[0].turned == pytest.approx(30.0, abs=0.01)
    assert found[0].beyond


def test_off_beyond_either_target():
    assert not BeliefError("butter", BELIEF_OFF, BELIEF_TURNED).beyond
    assert BeliefError("butter", BELIEF_OFF + 1e-4, 0.0).beyond
    assert BeliefError("butter", 0.0, BELIEF_TURNED + 0.1).beyond


class _Shifted:
    """Sees every object where it is, but the butter 3 cm along x and turned 30 degrees."""

    name = "shifted"

    def reset(self, scene) -> None:
        pass

    def observe(self, scene) -> Seen:
        sg = scene.scene_graph()
        poses = {n.name: n.pose for n in sg.nodes}
        p = poses["butter"]
        poses["butter"] = Pose.from_xyz_yaw(
            p.position[0] + 0.03, p.position[1], p.position[2], p.yaw + math.radians(30)
        )
        return Seen(GeometricSceneGraph.from_poses(poses, held=sg.held, world=KITCHEN))


@pytest.mark.parametrize("observer", [None, _Shifted()], ids=["ground truth", "shifted"])
def test_a_step_reports_how_far_its_belief_had_its_object(observer):
    env = KitchenStorageEnv(world=KITCHEN, **({"observer": observer} if observer else {}))
    try:
        goal = parse_goal("On(butter, shelf_a) & On(cherries, open_space)", world=KITCHEN)
        env.reset(seed=4, options=ResetOptions(goal))
        _, _, _, _, info = env.step(PickParams("butter"))
        (error,) = info["misbelieved"]
        assert error.obj == "butter"
        if observer is None:
            assert (error.off, error.turned) == (0.0, 0.0)
        else:
            assert error.off == pytest.approx(0.03, abs=2e-3)
            assert error.turned == pytest.approx(30.0, abs=1.0)
    finally:
        env.close()
