"""pick, place and push with the paper's parametrisation, each returning a typed outcome.

Transit and transfer motions come from the motion planner; the short approach and retreat
segments are straight in joint space between poses a few centimetres apart, and the push itself
follows a Cartesian straight line under physics. Nothing here raises for a failed motion: every
failure is an `Outcome` with a `Status` that says what went wrong.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

import numpy as np

from hsgplan.domain.objects import object_type
from hsgplan.domain.parameters import (
    PickParams,
    PlaceParams,
    PrimitiveParams,
    PushParams,
    place_xy,
    push_values,
)
from hsgplan.domain.world import GRIPPER_MAX_OPENING, SHELVES, SURFACES, Kind
from hsgplan.scene_graph.geometry import Pose, yaw_quat
from hsgplan.sim.motion import densify
from hsgplan.sim.outcome import Outcome, Status, verify
from hsgplan.sim.robot import REST, TIP_OFFSET, tilted, topdown
from hsgplan.sim.scene import Scene

APPROACH = 0.10  # m above a grasp or place pose where the straight final approach starts
GRASP_DEPTH = 0.035  # fingertips this far below an object's top, at most
FLOOR_GAP = 0.008  # and at least this far above what it stands on
DROP = 0.006  # a placed object is released this far above its support
PUSH_PITCH = math.radians(60)  # the hand leans forward to push (measured: upright hits boards)
PUSH_TIP_Z = 0.03
PUSH_STEP = 0.005
PUSH_SUBSTEPS = 6
RETREAT = 0.03

Frame = Callable[[], None]


def execute(scene: Scene, params: PrimitiveParams, on_frame: Frame | None = None) -> Outcome:
    """Run one primitive; `on_frame` is called along the way (for pictures)."""
    start = time.perf_counter()
    before = scene.scene_graph()
    if isinstance(params, PickParams):
        status, detail, expected = _pick(scene, params, on_frame)
    elif isinstance(params, PlaceParams):
        status, detail, expected = _place(scene, params, on_frame)
    else:
        status, detail, expected = _push(scene, params, on_frame)
    if status is Status.SUCCESS:
        status, detail = verify(scene, before, params.obj, expected)
    elif status not in (Status.INVALID,):
        scene.settle()
    return Outcome(status, detail, time.perf_counter() - start)


def _follow(scene: Scene, path: list[np.ndarray], on_frame: Frame | None) -> None:
    for q in densify(path):
        scene.robot.set_q(q)
        if on_frame:
            on_frame()


def _go(scene, q_goal, on_frame, ignore=()) -> bool:
    path = scene.motion_planner(ignore).plan(scene.robot.q(), q_goal)
    if path is None:
        return False
    _follow(scene, path, on_frame)
    return True


def _approach(scene: Scene, target: Pose, ignore: tuple[str, ...], seeds=None):
    """IK for a pose and for the pose APPROACH above it, with a free straight segment between."""
    with scene.robot.preserved():
        return _approach_unchecked(scene, target, ignore, seeds)


def _approach_unchecked(scene: Scene, target: Pose, ignore: tuple[str, ...], seeds=None):
    above = Pose(
        (target.position[0], target.position[1], target.position[2] + APPROACH), target.orientation
    )
    # The rest pose first: it keeps the arm in one well-conditioned elbow-up branch, from which
    # the straight approach and push lines stay reachable; the current joints come second.
    q_above = scene.robot.ik(above, scene.rng, seeds=seeds or [REST, scene.robot.q()])
    if q_above is None:
        return None
    q_at = scene.robot.ik(target, scene.rng, seeds=[q_above])
    if q_at is None:
        return None
    near = scene.checker(ignore=ignore, margin=0.001)
    if near.collides(q_above) or not near.segment_free(q_above, q_at):
        return None
    return q_above, q_at


# --- pick ------------------------------------------------------------------------------------


def _grasp_yaws(scene: Scene, obj: str) -> list[float]:
    pose = scene.pose(obj)
    if object_type(obj).kind is Kind.BOX:
        return [pose.yaw, pose.yaw + math.pi]  # close across the box's narrow (local x) side
    radial = math.atan2(pose.position[1], pose.position[0]) + math.pi / 2
    return [radial + k * math.pi / 4 for k in (0, 1, -1, 2)]


def _pick(scene: Scene, p: PickParams, on_frame):
    from hsgplan.domain.predicates import in_grasp

    robot, expected = scene.robot, in_grasp(p.obj)
    if p.obj not in scene.bodies:
        return Status.INVALID, f"'{p.obj}' is not in the scene", expected
    if robot.held_body is not None:
        return Status.INVALID, f"the gripper already holds '{scene.held()}'", expected
    t, pose = object_type(p.obj), scene.pose(p.obj)
    top = pose.position[2] + t.height / 2
    tip_z = max(top - GRASP_DEPTH, top - t.height + FLOOR_GAP)
    plan = None
    for yaw in _grasp_yaws(scene, p.obj):
        grasp = Pose((pose.position[0], pose.position[1], tip_z + TIP_OFFSET), topdown(yaw))
        plan = _approach(scene, grasp, ignore=(p.obj,))
        if plan:
            break
    if plan is None:
        return Status.NO_IK, f"no collision-free grasp of '{p.obj}'", expected
    q_above, q_at = plan
    robot.set_fingers(GRIPPER_MAX_OPENING)
    if not _go(scene, q_above, on_frame):
        return Status.NO_PATH, f"no path to above '{p.obj}'", expected
    _follow(scene, [q_above, q_at], on_frame)
    # The fingers close to the object's width, then a fixed constraint makes the grasp firm.
    robot.set_fingers(max(0.0, t.grasp_width - 0.002))
    robot.attach(scene.bodies[p.obj])
    _follow(scene, [q_at, q_above], on_frame)
    return Status.SUCCESS, "", expected


# --- place -----------------------------------------------------------------------------------


def _place(scene: Scene, p: PlaceParams, on_frame):
    from hsgplan.domain.predicates import on

    robot, expected = scene.robot, on(p.obj, p.target)
    if scene.held() != p.obj:
        return Status.INVALID, f"'{p.obj}' is not held", expected
    t = object_type(p.obj)
    if p.target in SURFACES:
        if p.x_bin is None or p.y_bin is None:
            return Status.INVALID, f"placing on '{p.target}' needs x and y bins", expected
        x, y = place_xy(p.obj, p.target, p.x_bin, p.y_bin)
        z = _surface_z(p.target)
        yaws = [scene.pose(p.obj).yaw + k * math.pi / 2 for k in (0, 1, -1, 2)]
    elif p.target in scene.bodies and p.target != p.obj:
        base = scene.pose(p.target)
        x, y = base.position[:2]
        z = base.position[2] + object_type(p.target).height / 2
        yaws = [base.yaw + k * math.pi / 2 for k in (0, 1, -1, 2)]
    else:
        return Status.INVALID, f"'{p.target}' is neither a surface nor another object", expected
    offset = robot.held_offset
    plan = None
    for yaw in yaws:
        obj_pose = Pose((x, y, z + t.height / 2 + DROP), yaw_quat(yaw))
        tcp = obj_pose.compose(offset.inverse())
        plan = _approach(scene, tcp, ignore=(p.obj,))
        if plan:
            break
    if plan is None:
        return Status.NO_IK, f"no collision-free way to place '{p.obj}' there", expected
    q_above, q_at = plan
    if not _go(scene, q_above, on_frame, ignore=(p.obj,)):
        return Status.NO_PATH, f"no path to above the place pose of '{p.obj}'", expected
    _follow(scene, [q_above, q_at], on_frame)
    robot.detach()
    robot.set_fingers(GRIPPER_MAX_OPENING)
    scene.settle()
    _follow(scene, [q_at, q_above], on_frame)
    return Status.SUCCESS, "", expected


def _surface_z(name: str) -> float:
    from hsgplan.domain.world import surface_rect

    return surface_rect(name).z


# --- push ------------------------------------------------------------------------------------


def _push(scene: Scene, p: PushParams, on_frame):
    from hsgplan.domain.predicates import inside

    robot = scene.robot
    if p.obj not in scene.bodies:
        return Status.INVALID, f"'{p.obj}' is not in the scene", None
    shelf = _prepush_shelf(scene, p.obj)
    expected = inside(p.obj, shelf) if shelf else None
    if robot.held_body is not None:
        return Status.INVALID, "the gripper is holding something", expected
    if shelf is None:
        return Status.INVALID, f"'{p.obj}' is not on a prepush region", expected
    angle, dist = push_values(p.angle_bin, p.dist_bin)
    u = np.array([math.cos(angle), math.sin(angle), 0.0])
    pose, t = scene.pose(p.obj), object_type(p.obj)
    reach = _extent_along(t, pose.yaw, angle)
    orn = tilted(angle, PUSH_PITCH)
    axis = Pose((0, 0, 0), orn).rotation[:, 2]
    tip0 = np.array([*pose.position[:2], min(PUSH_TIP_Z, t.height / 2)]) - (reach + 0.01) * u
    line = [tip0 + u * s for s in np.arange(0.0, dist + 1e-9, PUSH_STEP)]
    tcp = [Pose(tuple(tip - TIP_OFFSET * axis), orn) for tip in line]
    robot.set_fingers(0.0)
    qs = None
    random_seeds = [[scene.rng.uniform(robot.lower, robot.upper)] for _ in range(2)]
    for seeds in [[REST], [robot.q()], *random_seeds]:
        plan = _approach(scene, tcp[0], ignore=(p.obj,), seeds=seeds)
        if plan is None:
            continue
        q_above, q_start = plan
        qs = _follow_line(scene, tcp[1:], q_start)
        if qs is not None:
            break
    if qs is None:
        return Status.NO_PATH, f"no reachable, collision-free push line for '{p.obj}'", expected
    if not _go(scene, q_above, on_frame):
        return Status.NO_PATH, f"no path to above the push start of '{p.obj}'", expected
    _follow(scene, [q_above, q_start], on_frame)
    for q in qs[1:]:
        robot.drive_to(q, PUSH_SUBSTEPS)
        if on_frame:
            on_frame()
    back = robot.ik(
        Pose(tuple(np.add(tcp[-1].position, -RETREAT * u)), orn),
        scene.rng,
        seeds=[qs[-1]],
        restarts=0,
    )
    if back is not None:
        _follow(scene, [robot.q(), back], on_frame)
    scene.settle()
    up = robot.ik(
        Pose(tuple(np.add(robot.tcp().position, (0, 0, APPROACH))), orn),
        scene.rng,
        seeds=[robot.q()],
        restarts=0,
    )
    if up is not None:
        _follow(scene, [robot.q(), up], on_frame)
    robot.set_fingers(GRIPPER_MAX_OPENING)
    return Status.SUCCESS, "", expected


def _follow_line(scene: Scene, poses: list[Pose], q_start: np.ndarray):
    """Joints along a Cartesian line, each seeded by the last; None if any is out of reach."""
    qs, arena = [q_start], scene.checker(ignore=scene.objects, margin=0.0)
    with scene.robot.preserved():
        for target in poses:
            q = scene.robot.ik(target, scene.rng, seeds=[qs[-1]], restarts=0)
            if q is None or arena.collides(q) or np.max(np.abs(q - qs[-1])) > 0.3:
                return None
            qs.append(q)
    return qs


def _prepush_shelf(scene: Scene, obj: str) -> str | None:
    x, y = scene.pose(obj).position[:2]
    from hsgplan.domain.world import REGIONS

    for name, s in SHELVES.items():
        if REGIONS[s.prepush].contains(x, y, margin=0.01):
            return name
    return None


def _extent_along(t, yaw: float, angle: float) -> float:
    """How far the object reaches from its centre in a horizontal direction."""
    if t.kind is Kind.CAN:
        return t.size[0] / 2
    rel = angle - yaw
    return abs(math.cos(rel)) * t.size[0] / 2 + abs(math.sin(rel)) * t.size[1] / 2
