"""The arm and the gripper driven under physics: joint position control, the simulation stepped.

Every motion of the arm runs here, so what the arm or its load meets is pushed, toppled, or
stops it; nothing is moved by setting joints. A grasp holds what the fingers hold: they close
under a bounded force until they stop, and the object between them is fixed to the hand only
when both fingers touch it from opposite sides without sinking into it
(`GRASP_MAX_PENETRATION`); otherwise nothing is held, as the gripper's width then tells.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from hsgplan.sim.motion import densify
from hsgplan.sim.robot import ARM, FINGERS, MOTOR_FORCE, Panda

# Physics steps per waypoint of a densified path (STEP = 0.02 rad apart): at most 2.4 rad/s
# for the fastest joint, with a feed-forward velocity so that the arm tracks the path closely.
SUBSTEPS = 2
POSITION_GAIN = 0.5
VELOCITY_GAIN = 1.0
# The end of a path is held until every joint is this close (rad), for at most CATCH_UP steps;
# an arm held further than ARRIVED_TOL from it then is pressed against something.
REACHED_TOL = 5e-4
ARRIVED_TOL = 0.05
CATCH_UP = 240
# A joint further than this behind its waypoint means the arm is stopped by what it met: it
# halts where it is, as a robot's collision reflex would, and the motion is not finished.
BLOCKED_TOL = 0.15
FINGER_FORCE = 40.0  # N per finger
FINGER_STEPS = 120  # at most, to open or close the gripper
FINGER_STILL = 1e-3  # m/s: fingers slower than this have stopped
FINGER_THERE = 5e-4  # m: an opening this close to the one asked for is already there
# A grasp is made only when both fingers touch the object from opposite sides (their contact
# normals within about 45 degrees of opposite) and neither is inside it by more than this.
GRASP_MAX_PENETRATION = 0.002
OPPOSITE = -0.7
HOLD_MIN_WIDTH = 0.005  # m: a closed gripper wider than this holds something

Frame = Callable[[], None]


@dataclass(frozen=True)
class Driven:
    """How a driven motion ended: whether the arm reached the path's end, and the largest
    joint error (rad) where it stopped."""

    reached: bool
    error: float


def _command(robot: Panda, q: np.ndarray, velocity: np.ndarray) -> None:
    robot.bc.setJointMotorControlArray(
        robot.body,
        ARM,
        robot.bc.POSITION_CONTROL,
        targetPositions=[float(v) for v in q],
        targetVelocities=[float(v) for v in velocity],
        forces=[MOTOR_FORCE] * len(ARM),
        positionGains=[POSITION_GAIN] * len(ARM),
        velocityGains=[VELOCITY_GAIN] * len(ARM),
    )


def press_towards(robot: Panda, q: np.ndarray, steps: int) -> None:
    """The push line's stroke: the joints driven towards `q` for `steps` physics steps by the
    motors' own position control (its gains, no feed-forward velocity), whatever stands in
    the way: the push is meant to move what it meets."""
    robot.bc.setJointMotorControlArray(
        robot.body, ARM, robot.bc.POSITION_CONTROL, targetPositions=q, forces=[MOTOR_FORCE] * 7
    )
    for _ in range(steps):
        robot.bc.stepSimulation()


def _hold_here(robot: Panda) -> np.ndarray:
    """Hold the joints where they are now; returns them."""
    q = robot.q()
    _command(robot, q, np.zeros(len(ARM)))
    return q


def _halt(robot: Panda, target: np.ndarray) -> Driven:
    """The motion towards `target` was stopped: the arm holds where it is."""
    q = _hold_here(robot)
    return Driven(False, float(np.max(np.abs(q - target))))


def drive_path(
    robot: Panda, path: Sequence[np.ndarray], time_step: float, on_frame: Frame | None = None
) -> Driven:
    """Drive the arm along a joint path under physics, then hold its end.

    Args:
        robot: the arm; the physics client is its own.
        path: joint waypoints (7 floats each), the first near where the arm is.
        time_step: the simulation's step in seconds (for the feed-forward velocity).
        on_frame: called after each waypoint, for pictures.
    """
    bc = robot.bc
    waypoints = densify(list(path))
    dt = SUBSTEPS * time_step
    for a, b in zip(waypoints, waypoints[1:], strict=False):
        _command(robot, b, (b - a) / dt)
        for _ in range(SUBSTEPS):
            bc.stepSimulation()
        if np.max(np.abs(robot.q() - b)) > BLOCKED_TOL:
            return _halt(robot, b)
        if on_frame is not None:
            on_frame()
    return hold_until_reached(robot, waypoints[-1])


def hold_until_reached(robot: Panda, q: np.ndarray) -> Driven:
    """Hold the arm at q, stepping physics until it is there (or CATCH_UP steps)."""
    _command(robot, q, np.zeros(len(ARM)))
    error = float(np.max(np.abs(robot.q() - q)))
    for _ in range(CATCH_UP):
        if error < REACHED_TOL:
            break
        robot.bc.stepSimulation()
        error = float(np.max(np.abs(robot.q() - q)))
    if error > BLOCKED_TOL:
        _halt(robot, q)
    return Driven(error <= ARRIVED_TOL, error)


def drive_fingers(robot: Panda, opening: float, force: float = FINGER_FORCE) -> float:
    """Open or close the gripper towards `opening` (m between the fingers) under a bounded
    force, stepping physics until the fingers stop; returns the width they stopped at."""
    bc = robot.bc
    robot.closing = opening == 0.0
    if not robot.closing and abs(robot.finger_opening() - opening) < FINGER_THERE:
        return robot.finger_opening()
    _hold_here(robot)  # the arm stays where it is meanwhile
    bc.setJointMotorControlArray(
        robot.body,
        FINGERS,
        bc.POSITION_CONTROL,
        targetPositions=[opening / 2] * len(FINGERS),
        forces=[force] * len(FINGERS),
    )
    for step in range(FINGER_STEPS):
        bc.stepSimulation()
        if step >= 4:
            speeds = [abs(s[1]) for s in bc.getJointStates(robot.body, FINGERS)]
            if max(speeds) < FINGER_STILL:
                break
    return robot.finger_opening()


def body_in_grasp(robot: Panda, bodies: Sequence[int]) -> int | None:
    """The body both fingers touch from opposite sides, neither sunk into it by more than
    GRASP_MAX_PENETRATION: what closed fingers hold. None when there is none."""
    bc = robot.bc
    for body in bodies:
        normals = []
        for finger in FINGERS:
            contacts = bc.getContactPoints(robot.body, body, finger, -1)
            if not contacts:
                break
            if min(c[8] for c in contacts) < -GRASP_MAX_PENETRATION:
                break
            n = np.sum([c[7] for c in contacts], axis=0)
            normals.append(n / (np.linalg.norm(n) or 1.0))
        else:
            if float(np.dot(normals[0], normals[1])) < OPPOSITE:
                return body
    return None


def rests_in_hand(robot: Panda, body: int) -> bool:
    """Whether the body touches the robot and nothing else: off whatever it stood on, it is
    held up by the hand alone (by a grasp's constraint or by friction). Read from the contacts
    of the last physics step."""
    contacts = robot.bc.getContactPoints(bodyA=body)
    return bool(contacts) and all(c[2] == robot.body for c in contacts)


def holds_something(robot: Panda) -> bool:
    """What the gripper tells the robot: fingers told to close, held apart by something."""
    return robot.closing and robot.finger_opening() > HOLD_MIN_WIDTH
