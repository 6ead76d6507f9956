"""The arm under physics: what it sweeps through moves, and a grasp holds what the fingers hold."""

import numpy as np
import pytest

from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.parameters import PickParams
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.actuation import (
    HOLD_MIN_WIDTH,
    body_in_grasp,
    drive_fingers,
    drive_path,
    holds_something,
)
from hsgplan.sim.belief_world import BeliefWorld
from hsgplan.sim.motion_plans import MotionPlan
from hsgplan.sim.outcome import disturbances
from hsgplan.sim.primitives import run_plan
from hsgplan.sim.robot import FINGERS, TIP_OFFSET, topdown
from hsgplan.sim.scene import TIME_STEP, Scene

from .conftest import standing

CAN = "tomato_soup"
DIAMETER = 0.070


def _low_hand(scene: Scene, x: float, y: float) -> np.ndarray:
    """Joints that put the closed hand's fingertips 4 cm above the table at (x, y)."""
    q = scene.robot.ik(Pose((x, y, 0.05), topdown(0.0)), scene.rng)
    assert q is not None
    return q


def test_an_arm_swept_through_a_resting_can_pushes_it():
    with Scene((CAN,), seed=0, poses={CAN: standing(CAN, 0.5, 0.0)}, world=KITCHEN) as scene:
        scene.settle()
        start, end = _low_hand(scene, 0.5, 0.16), _low_hand(scene, 0.5, -0.16)
        scene.robot.set_q(start)
        drive_fingers(scene.robot, 0.0)
        before = scene.poses()
        drive_path(scene.robot, [start, end], TIME_STEP)
        moved = disturbances(before, scene.poses(), acted_on="")
        assert [d.obj for d in moved] == [CAN]
        assert moved[0].moved > 0.02  # not swept through: pushed aside or knocked over


def test_a_path_into_the_table_is_stopped_and_says_so():
    with Scene((CAN,), seed=0, world=KITCHEN) as scene:
        above = _low_hand(scene, 0.5, 0.0)
        scene.robot.set_q(above)
        into = scene.robot.ik(Pose((0.5, 0.0, -0.05), topdown(0.0)), scene.rng)
        assert into is not None
        driven = drive_path(scene.robot, [above, into], TIME_STEP)
        assert not driven.reached
        # the table stopped the hand short of the 5 cm into it the path asked for
        assert scene.robot.tcp().position[2] > -0.02


def _pick_believed_off(offset: tuple[float, float]):
    """A can on the table, the robot believing it `offset` (m) away; the pick planned in the
    belief and run in the scene. Returns the scene, the plan and the can's pose before."""
    truth = standing(CAN, 0.5, 0.1)
    believed = Pose((0.5 + offset[0], 0.1 + offset[1], truth.position[2]), truth.orientation)
    scene = Scene((CAN,), seed=0, poses={CAN: truth}, world=KITCHEN)
    scene.settle()
    start = scene.pose(CAN)
    world = BeliefWorld((CAN,), seed=0, world=KITCHEN)
    try:
        world.believe(GeometricSceneGraph.from_poses({CAN: believed}, world=KITCHEN))
        plan = world.plan(PickParams(CAN))
    finally:
        world.close()
    assert isinstance(plan, MotionPlan)
    return scene, plan, start


def _closing_direction(plan: MotionPlan) -> np.ndarray:
    """The horizontal direction the fingers close along, from the plan's hand at the grasp."""
    with Scene((), seed=0, world=KITCHEN) as model:
        model.robot.set_q(plan.q_at)
        axis = model.robot.tcp().rotation[:, 1]
    return axis[:2] / np.linalg.norm(axis[:2])


def test_a_can_believed_15_mm_off_is_grasped_where_physics_puts_it():
    # 15 mm across the closing direction: the fingers (7.5 mm of room a side) come down
    # beside it, close, and hold it off the hand's centre.
    scene, plan, start = _pick_believed_off((0.0, 0.0))
    scene.close()
    across = np.array([-1.0, 1.0]) * _closing_direction(plan)[::-1]
    scene, plan, start = _pick_believed_off(tuple(0.015 * across))
    with scene:
        assert run_plan(scene, plan) is None
        assert scene.held() == CAN
        # the width reads the can's diameter: what the robot knows it holds
        assert scene.robot.finger_opening() == pytest.approx(DIAMETER, abs=0.003)
        assert holds_something(scene.robot)
        offset = scene.robot.held_offset.position
        assert np.hypot(offset[0], offset[1]) > 0.005  # held off the hand's centre
        assert scene.pose(CAN).position[2] > start.position[2] + 0.05  # taken up


def test_a_can_believed_15_mm_off_along_the_closing_fingers_follows_physics():
    # 15 mm along the closing direction, a finger comes down on the can's rim: whatever
    # physics makes of it, the gripper's width tells the robot the same as the simulator.
    scene, plan, _ = _pick_believed_off((0.0, 0.0))
    scene.close()
    along = _closing_direction(plan)
    scene, plan, start = _pick_believed_off(tuple(0.015 * along))
    with scene:
        run_plan(scene, plan)
        assert holds_something(scene.robot) == (scene.held() == CAN)
        assert scene.pose(CAN).distance(start) > 0.005  # the finger's touch moved it


def test_fingers_closing_on_nothing_hold_nothing_and_read_closed():
    scene, plan, start = _pick_believed_off((0.0, 0.06))
    with scene:
        assert run_plan(scene, plan) is None
        assert scene.held() is None
        assert scene.robot.finger_opening() < HOLD_MIN_WIDTH
        assert not holds_something(scene.robot)
        assert scene.pose(CAN).distance(start) < 0.005


def test_fingers_both_on_top_of_a_can_are_no_grasp():
    with Scene((CAN,), seed=0, poses={CAN: standing(CAN, 0.5, 0.0)}, world=KITCHEN) as scene:
        scene.settle()
        robot = scene.robot
        top = scene.pose(CAN).position[2] + 0.083 / 2
        q = robot.ik(Pose((0.5, 0.0, top + TIP_OFFSET - 0.005), topdown(0.0)), scene.rng)
        assert q is not None
        robot.set_fingers(0.0)
        robot.set_q(q)
        drive_fingers(robot, 0.0)
        touching = [
            bool(scene.bc.getContactPoints(robot.body, scene.bodies[CAN], f, -1)) for f in FINGERS
        ]
        assert touching == [True, True]  # both fingers touch it, from the same side
        assert body_in_grasp(robot, (scene.bodies[CAN],)) is None


def test_a_stopped_arm_is_the_failure_unless_the_effect_holds_or_something_fell():
    from hsgplan.sim.outcome import Status, stopped_outcome

    why = "the arm was stopped on its way by something it met"
    assert stopped_outcome(Status.DROPPED, "nothing held", why) == (Status.BLOCKED, why)
    assert stopped_outcome(Status.SUCCESS, "", why) == (Status.SUCCESS, "")
    fell = (Status.KNOCKED_OVER, "'butter' toppled")
    assert stopped_outcome(*fell, why) == fell
    assert stopped_outcome(Status.DROPPED, "nothing held", None) == (Status.DROPPED, "nothing held")
