"""Where a step's arm could have touched anything (`sim/reach.py`), on hand-built boxes and on
the canonical scene; and the objects a model's arm stands in (`motion_plans.overlapped`)."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from hsgplan.domain.parameters import PickParams
from hsgplan.sim.motion_plans import MotionPlan, overlapped, plan_primitive
from hsgplan.sim.reach import REACH_MARGIN, SWEEP_STEP, driven, near, segment_distance, swept_boxes
from hsgplan.sim.robot import REST
from hsgplan.sim.sensing import Box

UNIT = Box((0.0, 0.0, 0.0), (1.0, 1.0, 1.0))


def test_a_point_is_near_a_box_within_the_margin_and_not_beyond():
    assert near([(0.5, 0.5, 0.5)], [UNIT], None)  # inside
    assert near([(1.0 + REACH_MARGIN - 1e-6, 0.5, 0.5)], [UNIT], None)
    assert not near([(1.0 + REACH_MARGIN + 1e-6, 0.5, 0.5)], [UNIT], None)
    # past a corner the distance is Euclidean, not per axis
    corner = 1.0 + 0.8 * REACH_MARGIN
    assert not near([(corner, corner, corner)], [UNIT], None)


def test_a_point_is_near_the_acted_objects_track():
    track = ((0.0, 0.0, 0.0), (0.4, 0.0, 0.0))
    assert near([(0.2, REACH_MARGIN - 1e-6, 0.0)], [], track)
    assert not near([(0.2, REACH_MARGIN + 1e-6, 0.0)], [], track)
    assert not near([(0.4 + REACH_MARGIN + 1e-6, 0.0, 0.0)], [], track)
    assert not near([], [UNIT], track)


@given(st.lists(st.floats(-2, 2), min_size=3, max_size=3), st.floats(0, 1))
def test_a_segment_is_no_farther_than_its_ends_nor_than_any_point_of_it(p, t):
    a, b = np.array([0.1, -0.2, 0.3]), np.array([0.5, 0.4, -0.1])
    d = segment_distance(p, a, b)
    assert d <= min(np.linalg.norm(np.subtract(p, a)), np.linalg.norm(np.subtract(p, b))) + 1e-9
    assert d <= np.linalg.norm(np.subtract(p, a + t * (b - a))) + 1e-9


def _plan(scene, obj="butter") -> MotionPlan:
    plan = plan_primitive(scene, PickParams(obj))
    assert isinstance(plan, MotionPlan)
    return plan


def test_the_sweep_samples_every_joint_motion_finely_and_ends_where_the_plan_does(scene):
    plan = _plan(scene)
    joints = driven(plan)
    steps = [np.abs(b - a).max() for a, b in zip(joints, joints[1:], strict=False)]
    assert max(steps) <= SWEEP_STEP + 1e-9
    assert np.allclose(joints[0], plan.path[0]) and np.allclose(joints[-1], plan.q_at)


def test_the_sweep_reaches_the_picked_object_and_not_the_far_corner_and_puts_the_arm_back(scene):
    plan = _plan(scene)
    q = scene.robot.q()
    boxes = swept_boxes(scene.robot, driven(plan), below=0.05)
    assert np.allclose(scene.robot.q(), q)
    assert near([scene.pose("butter").position], boxes, None)
    assert not near([(0.9, 0.6, 0.05)], boxes, None)
    grown = swept_boxes(scene.robot, [plan.q_at], below=0.05)
    plain = swept_boxes(scene.robot, [plan.q_at])
    for g, p in zip(grown, plain, strict=True):
        assert g.low[2] == pytest.approx(p.low[2] - 0.05) and g.high == p.high


def test_the_objects_the_arm_stands_in_are_named_and_none_where_it_stands_free(scene):
    scene.robot.set_q(REST)
    assert overlapped(scene) == ()
    x, y, z = scene.robot.tcp().position
    pose = scene.pose("cherries")
    scene.set_pose("cherries", type(pose)((x, y, z + 0.05), pose.orientation))  # in the hand
    assert overlapped(scene) == ("cherries",)


def test_the_hands_horizontal_reach_is_the_arms():
    # top-down at every height a held object may rise to, in directions all round: the
    # arm reaches REACH_MAX_XY and does not reach 14 cm beyond it (a larger constant would
    # accept scenes whose places the arm cannot reach)
    import math

    import pybullet as p
    from pybullet_utils.bullet_client import BulletClient

    from hsgplan.domain.scene import REACH_MAX_XY, REACH_MAX_Z
    from hsgplan.scene_graph.geometry import Pose
    from hsgplan.sim.robot import Panda, topdown

    bc = BulletClient(p.DIRECT)
    try:
        robot = Panda(bc, visuals=False)

        def reaches(r, z, direction):
            # each point its own random restarts, so that no point's answer hangs on the others
            rng = np.random.default_rng(abs(round(1000 * (r + z + direction))))
            at = (r * math.cos(direction), r * math.sin(direction), z)
            return any(
                robot.ik(Pose(at, topdown(direction + turn)), rng, restarts=12) is not None
                for turn in (0.0, math.pi / 2)
            )

        for z in (0.02, REACH_MAX_Z):
            for degrees in (0, 90, 180, -90):
                direction = math.radians(degrees)
                assert reaches(REACH_MAX_XY, z, direction), (z, degrees)
                assert not reaches(REACH_MAX_XY + 0.14, z, direction), (z, degrees)
    finally:
        bc.disconnect()
