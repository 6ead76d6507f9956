"""The robot's own model of the scene: a second physics client with the arena, the arm and the
objects where the robot believes them (a camera observer's belief), or where they truly are
(the ground truth observer's, `know`): dry runs, trials and plans are made in it, never in the
simulated scene.

Every primitive is planned here (inverse kinematics, collision checks, paths, push lines), so
that the arm acts at the believed poses; the simulated scene only runs the planned joint
motions (`sim.primitives.run_plan`). The model's arm follows the real one's joints (its
encoders), and an object the robot took up rides in the model's hand with the grasp as planned:
what the robot knows of where its hand holds it, and where it let it go. Objects the robot has
never seen are parked out of the way: no pose, no obstacle.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from hsgplan.domain.parameters import PickParams, PlaceParams, PushParams, push_carry, push_values
from hsgplan.domain.scene import World
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.motion_plans import MotionPlan, PlanFailure, plan_primitive
from hsgplan.sim.scene import Scene
from hsgplan.sim.sensing import Box


class BeliefWorld:
    """Args:
    objects: the goal's object names (each gets a body, parked until believed somewhere).
    seed: seeds the model's inverse-kinematics restarts and motion planning.
    world: the arena and object types the robot knows its world by.
    """

    def __init__(self, objects: Iterable[str], seed: int, world: World) -> None:
        self.scene = Scene(objects, seed, visuals=False, world=world)  # a model: never pictured
        self.holding: str | None = None

    def close(self) -> None:
        self.scene.close()

    def believe(self, sg: GeometricSceneGraph) -> None:
        """Put every object where the belief has it; one it has no pose for is parked. The
        held object stays in the model's hand."""
        for name in self.scene.objects:
            if name == self.holding:
                continue
            if name in sg.objects:
                self.scene.set_pose(name, sg.pose(name))
            else:
                self.scene.park(name)

    def know(self, sg: GeometricSceneGraph, q: np.ndarray, fingers: float) -> None:
        """The model put to the truth, under the ground truth observer: the arm at the real
        joints and finger opening, every object at its pose, and the held one in the model's
        hand where it truly is."""
        robot = self.scene.robot
        robot.detach()
        self.holding = None
        robot.set_fingers(fingers)
        robot.set_q(q)
        self.believe(sg)
        if sg.held is not None:
            robot.attach(self.scene.bodies[sg.held])
            self.holding = sg.held

    def follow(self, q: np.ndarray) -> None:
        """The model's arm to the real arm's joints (carrying what it holds)."""
        self.scene.robot.set_q(q)

    def arm(self) -> tuple[Box, ...]:
        """The model's arm as boxes, link by link (`Panda.boxes`)."""
        return self.scene.robot.boxes()

    def plan(self, params) -> MotionPlan | PlanFailure:
        """A primitive planned at the believed poses; nothing in the model moves."""
        return plan_primitive(self.scene, params)

    def held_pose(self) -> Pose | None:
        return None if self.holding is None else self.scene.pose(self.holding)

    def executed(self, plan: MotionPlan, gripper_holds: bool) -> tuple[str, Pose] | None:
        """The model after the real arm ran `plan`: a pick whose fingers closed on something
        holds the object it was planned for (the robot's own record), by the grasp as
        planned; a place lets it go where the planned hand put it; a push leaves its object
        where its stroke ends (`_stroke_end`). Returns the object let go or pushed and where,
        if any. The arm is left where the plan ends (`follow` puts it right)."""
        robot = self.scene.robot
        if isinstance(plan.params, PickParams) and gripper_holds:
            robot.set_q(plan.q_at)
            robot.set_fingers(plan.grip)
            robot.attach(self.scene.bodies[plan.params.obj])
            self.holding = plan.params.obj
            robot.set_q(plan.q_above)
            return None
        if isinstance(plan.params, PlaceParams) and self.holding is not None:
            robot.set_q(plan.q_at)
            robot.detach()
            released = self.holding, robot.released[1]
            self.holding = None
            robot.set_q(plan.q_above)
            return released
        if isinstance(plan.params, PushParams) and plan.push_direction is not None:
            return plan.params.obj, self._stroke_end(plan)
        return None

    def _stroke_end(self, plan: MotionPlan) -> Pose:
        """Where a push's stroke leaves its object in the model: its centre carried along the
        push as far as the fingertips carry it (`push_carry`; it may slide on, or lag): what
        the robot's own motion says of an object it may no longer see."""
        start = self.scene.pose(plan.params.obj)
        _, dist = push_values(plan.params.angle_bin, plan.params.dist_bin)
        ux, uy = plan.push_direction
        x, y, z = start.position
        moved = push_carry(dist)
        return Pose((x + ux * moved, y + uy * moved, z), start.orientation)

    def dropped(self) -> None:
        """The gripper no longer feels the object it held: the model lets it go too."""
        self.scene.robot.detach()
        self.holding = None
