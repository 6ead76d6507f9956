"""The Franka Panda from `pybullet_data`: kinematics, inverse kinematics, gripper, grasp.

Joint states are set directly only for queries (inverse kinematics, collision checks, a
model's arm); the real arm is driven under physics by `sim.actuation`. A grasp is made firm by
a fixed constraint between the hand and the object where the fingers hold it (`attach`).
"""

from __future__ import annotations

import contextlib
import hashlib
import math
import os
import re
import tempfile
from collections.abc import Iterator
from functools import cache
from pathlib import Path

import numpy as np
import pybullet_data
from pybullet_utils.bullet_client import BulletClient

from hsgplan.domain.world import GRIPPER_MAX_OPENING
from hsgplan.scene_graph.geometry import Pose, matrix_to_quat
from hsgplan.sim.sensing import Box

ARM = tuple(range(7))
FINGERS = (9, 10)
HAND = (8, 9, 10)  # the hand and its fingers: placed by the TCP pose alone, whatever the arm
TCP = 11  # panda_grasptarget, between the fingers
TIP_OFFSET = 0.011  # the fingertips lie this far beyond the TCP along the hand's z axis
REST = np.array([0.0, -0.3, 0.0, -2.2, 0.0, 2.0, math.pi / 4])
# Measured for this robot: fewer iterations leave centimetre errors near the workspace edge.
IK_ITERATIONS = 200
IK_THRESHOLD = 1e-4
IK_POS_TOL = 0.004
IK_ANG_TOL = 0.05
MOTOR_FORCE = 300.0


def topdown(closing_yaw: float) -> tuple[float, float, float, float]:
    """Hand pointing down, fingers closing along the world direction at `closing_yaw`."""
    y = np.array([math.cos(closing_yaw), math.sin(closing_yaw), 0.0])
    z = np.array([0.0, 0.0, -1.0])
    return matrix_to_quat(np.column_stack([np.cross(y, z), y, z]))


def tilted(direction_yaw: float, pitch: float) -> tuple[float, float, float, float]:
    """Hand leaning `pitch` from vertical towards `direction_yaw`, fingers across it (pushing)."""
    u = np.array([math.cos(direction_yaw), math.sin(direction_yaw), 0.0])
    z = math.sin(pitch) * u + np.array([0.0, 0.0, -math.cos(pitch)])
    y = np.array([-u[1], u[0], 0.0])
    return matrix_to_quat(np.column_stack([np.cross(y, z), y, z]))


@cache
def panda_urdf(visuals: bool = True) -> str:
    """The Panda's URDF: pybullet_data's, or (without `visuals`) a copy of it without its
    visual meshes, which load in a fifth of the time (measured: 18 against 90 ms) and which
    nothing but pictures reads. Links, joints, inertias and collision shapes are the file's
    own, so physics and every query are the same; the copy is written once per machine."""
    folder = Path(pybullet_data.getDataPath()) / "franka_panda"
    original = folder / "panda.urdf"
    if visuals:
        return str(original)
    text = original.read_text()
    text = re.sub(r"\s*<visual>.*?</visual>", "", text, flags=re.S)
    text = text.replace("package://", f"{folder}/")  # the meshes stay where they are
    digest = hashlib.sha256(text.encode()).hexdigest()[:16]
    path = Path(tempfile.gettempdir()) / f"hsgplan-panda-{digest}.urdf"
    if not path.is_file():
        # Written aside and renamed: workers starting together never read half a file.
        fd, partial = tempfile.mkstemp(dir=path.parent, suffix=".urdf")
        with os.fdopen(fd, "w") as f:
            f.write(text)
        os.replace(partial, path)
    return str(path)


class Panda:
    """The arm in one physics client. Joint values are numpy arrays of 7 floats.

    Args:
        bc: the physics client.
        visuals: load the visual meshes (for pictures of the arm); physics is the same either
            way (`panda_urdf`).
    """

    def __init__(self, bc: BulletClient, visuals: bool = True) -> None:
        self.bc = bc
        bc.setAdditionalSearchPath(pybullet_data.getDataPath())
        self.body = bc.loadURDF(panda_urdf(visuals), useFixedBase=True)
        info = [bc.getJointInfo(self.body, j) for j in ARM]
        self.lower = np.array([i[8] for i in info])
        self.upper = np.array([i[9] for i in info])
        self.grasp_constraint: int | None = None
        # whether the fingers were last told to close (`sim.actuation.drive_fingers`): a closed
        # gripper's width then says whether it holds something
        self.closing = False
        self.held_body: int | None = None
        self.held_offset: Pose | None = None
        # The last object let go and its pose as the hand let it go (the arm's kinematics and
        # the grasp): what the robot itself knows of where it put something.
        self.released: tuple[int, Pose] | None = None
        self.set_q(REST)
        self.set_fingers(GRIPPER_MAX_OPENING)
        self.hold_position()

    # --- state -----------------------------------------------------------------------

    def boxes(self) -> tuple[Box, ...]:
        """Each link's axis-aligned bounding box where the joints put it (fingers included)."""
        links = range(-1, self.bc.getNumJoints(self.body))
        return tuple(Box(*map(tuple, self.bc.getAABB(self.body, j))) for j in links)

    def q(self) -> np.ndarray:
        return np.array([s[0] for s in self.bc.getJointStates(self.body, ARM)])

    def q_in_limits(self) -> np.ndarray:
        """The joints clipped to their limits, where planning starts: a joint driven to its
        limit under physics may end a hair past it, which OMPL takes for an invalid start
        (measured: 2e-5 rad past, every path refused)."""
        return np.clip(self.q(), self.lower, self.upper)

    def set_q(self, q: np.ndarray) -> None:
        """Set the arm's joints directly; a held object is carried along."""
        for j, v in zip(ARM, q, strict=True):
            self.bc.resetJointState(self.body, j, float(v))
        if self.held_body is not None:
            self._carry_held()

    def _carry_held(self) -> None:
        # PyBullet's own transform product: collision checks call this thousands of times.
        s = self.bc.getLinkState(self.body, TCP, computeForwardKinematics=True)
        off = self.held_offset
        pos, orn = self.bc.multiplyTransforms(s[4], s[5], off.position, off.orientation)
        self.bc.resetBasePositionAndOrientation(self.held_body, pos, orn)

    def set_q_for_query(self, q: np.ndarray) -> None:
        """`set_q` for geometric queries (collision checks): one call for all seven joints,
        a fifth of the time of seven (measured). Not for inverse kinematics, whose answers it
        perturbs in the last digits (measured: one push outcome in a thousand changed). Later
        physics differs in the last digits too (measured), so swapping one for the other in any
        caller means collecting the motion data again."""
        self.bc.resetJointStatesMultiDof(self.body, ARM, [[float(v)] for v in q])
        if self.held_body is not None:
            self._carry_held()

    def set_fingers(self, opening: float) -> None:
        for j in FINGERS:
            self.bc.resetJointState(self.body, j, opening / 2)

    def finger_opening(self) -> float:
        return float(sum(s[0] for s in self.bc.getJointStates(self.body, FINGERS)))

    def tcp(self) -> Pose:
        s = self.bc.getLinkState(self.body, TCP, computeForwardKinematics=True)
        return Pose(tuple(s[4]), tuple(s[5]))

    def hold_position(self, fingers: float | None = None) -> None:
        """Motors hold the current joints (and finger opening) while physics steps."""
        q = self.q()
        self.bc.setJointMotorControlArray(
            self.body, ARM, self.bc.POSITION_CONTROL, targetPositions=q, forces=[MOTOR_FORCE] * 7
        )
        opening = self.finger_opening() if fingers is None else fingers
        self.bc.setJointMotorControlArray(
            self.body,
            FINGERS,
            self.bc.POSITION_CONTROL,
            targetPositions=[opening / 2] * 2,
            forces=[40.0] * 2,
        )

    @contextlib.contextmanager
    def preserved(self) -> Iterator[None]:
        """Checks and IK move the arm and fingers; this puts them (and what is held) back after."""
        q, opening = self.q(), self.finger_opening()
        held = self.held_body
        # where physics holds it, which the grasp's constraint keeps within a hair of nominal
        held_at = None if held is None else self.bc.getBasePositionAndOrientation(held)
        try:
            yield
        finally:
            self.set_fingers(opening)
            self.set_q(q)
            if held is not None and held == self.held_body:
                self.bc.resetBasePositionAndOrientation(held, *held_at)

    # --- kinematics --------------------------------------------------------------------

    def ik(
        self,
        target: Pose,
        rng: np.random.Generator,
        seeds: list[np.ndarray] | None = None,
        restarts: int = 4,
        rest_fallback: bool = True,
        threshold: float = IK_THRESHOLD,
    ) -> np.ndarray | None:
        """Joints that put the TCP at `target`, or None. Tries the seeds, then the rest pose
        (unless `rest_fallback` is off or it was a seed), then random restarts.

        The arm is left where it was; the result is clipped to the joint limits and checked by
        forward kinematics, since PyBullet's solver returns its best effort without a verdict.
        """
        saved = self.q()
        starts = list(seeds or [])
        # The solver is deterministic: a start tried once gives the same answer again.
        if rest_fallback and not any(np.array_equal(s, REST) for s in starts):
            starts.append(REST)
        starts += [rng.uniform(self.lower, self.upper) for _ in range(restarts)]
        found = None
        for start in starts:
            self._set_arm(start)
            sol = self.bc.calculateInverseKinematics(
                self.body,
                TCP,
                target.position,
                target.orientation,
                lowerLimits=list(self.lower) + [0.0, 0.0],
                upperLimits=list(self.upper) + [0.04, 0.04],
                jointRanges=list(self.upper - self.lower) + [0.04, 0.04],
                restPoses=list(start) + [0.02, 0.02],
                maxNumIterations=IK_ITERATIONS,
                residualThreshold=threshold,
            )
            q = np.clip(np.array(sol[:7]), self.lower, self.upper)
            self._set_arm(q)
            if self._close_to(target):
                found = q
                break
        self._set_arm(saved)
        return found

    def _set_arm(self, q: np.ndarray) -> None:
        for j, v in zip(ARM, q, strict=True):
            self.bc.resetJointState(self.body, j, float(v))

    def _close_to(self, target: Pose) -> bool:
        now = self.tcp()
        if now.distance(target) > IK_POS_TOL:
            return False
        d = abs(float(np.dot(now.orientation, target.orientation)))
        return 2 * math.acos(min(1.0, d)) < IK_ANG_TOL

    # --- grasp ---------------------------------------------------------------------------

    def attach(self, body: int) -> None:
        """Fix the object to the hand where it is now (the fingers have closed on it)."""
        obj = Pose(*self.bc.getBasePositionAndOrientation(body))
        self.held_offset = obj.relative_to(self.tcp())
        self.held_body = body
        self.closing = True
        self.grasp_constraint = self.bc.createConstraint(
            self.body,
            TCP,
            body,
            -1,
            self.bc.JOINT_FIXED,
            (0, 0, 0),
            self.held_offset.position,
            (0, 0, 0),
            self.held_offset.orientation,
        )
        self.bc.changeConstraint(self.grasp_constraint, maxForce=200.0)

    def carry(self, body: int) -> None:
        """Take as held an object the closed fingers lifted by friction alone (`attach` makes
        a constraint only on opposite faces): planning's queries carry it with the hand, while
        under physics friction alone holds it, until it slips (`Scene.feel_hold`)."""
        obj = Pose(*self.bc.getBasePositionAndOrientation(body))
        self.held_offset = obj.relative_to(self.tcp())
        self.held_body = body

    def grip(self) -> tuple[int | None, bool]:
        """What the hand holds (a body or None) and whether by friction alone: what a saved
        physics state leaves out (`regrip` makes it again after a restore)."""
        return self.held_body, self.held_body is not None and self.grasp_constraint is None

    def regrip(self, grip: tuple[int | None, bool]) -> None:
        """After a physics state was restored, the hand let go: it holds again what `grip`
        said (`Scene.back_to`)."""
        body, by_friction = grip
        if body is not None:
            (self.carry if by_friction else self.attach)(body)

    def detach(self) -> None:
        if self.held_body is not None and self.held_offset is not None:
            self.released = (self.held_body, self.tcp().compose(self.held_offset))
        if self.grasp_constraint is not None:
            self.bc.removeConstraint(self.grasp_constraint)
        self.grasp_constraint = self.held_body = self.held_offset = None
