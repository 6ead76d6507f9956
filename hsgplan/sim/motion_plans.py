"""The planning half of each primitive: inverse kinematics, approach lines and the transit or
transfer path, computed without moving anything.

Planning is separate from execution so that a parameter choice can be checked (a dry run)
before it is spent, and so that execution replays exactly what was checked.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.parameters import (
    PUSH_LEAD,
    PickParams,
    PlaceParams,
    PrimitiveParams,
    extent_along,
    place_xy,
    place_yaw,
    push_carry,
    push_values,
)
from hsgplan.domain.predicates import Literal, in_grasp, inside, on
from hsgplan.domain.world import GRIPPER_MAX_OPENING, Kind, World
from hsgplan.scene_graph.geometry import Pose, yaw_quat
from hsgplan.sim.collision import SAFETY_MARGIN
from hsgplan.sim.outcome import Status
from hsgplan.sim.robot import REST, TIP_OFFSET, tilted, topdown
from hsgplan.sim.scene import Scene

LIFT = 0.12  # m a hand rises before crossing, when a straight joint motion collides
APPROACH = 0.10  # m above a grasp or place pose where the straight final approach starts
GRASP_DEPTH = 0.035  # fingertips this far below an object's top, at most
FLOOR_GAP = 0.008  # and at least this far above what it stands on
PREGRASP_ROOM = 0.015  # the fingers open this much wider than the object before a grasp
DROP = 0.006  # a placed object is released this far above its support
PUSH_PITCH = math.radians(60)  # the hand leans forward to push (measured: upright hits boards)
PUSH_TIP_Z = 0.03
PUSH_STEP = 0.005
PUSH_SLACK = 0.025  # m a push's bound must reach past a shelf's front (see _plan_push)
IK_BRANCHES = 6  # random restarts for an approach whose first IK solutions collide
LINE_IK_EVERY = 8  # push waypoints (PUSH_STEP apart) per inverse kinematics along the line
# m: the solver stops this close to a line pose. Measured over 195 steps of 40 lines: as many
# solved as with a tenth of a millimetre, in a third of the time.
LINE_IK_TOL = 1e-3
MAX_JOINT_JUMP = 0.3  # rad between IK solutions along a push line: more means a branch flip


@dataclass(frozen=True)
class MotionPlan:
    """Everything execution needs: the path to `q_above`, the straight approach to `q_at`
    (through the joints of `descent`, which keep the hand on the straight line: a straight
    line in joint space bows the hand sideways by as much as a finger's clearance), and for a
    push the joints along the push line. `grip` is the finger opening to close to."""

    params: PrimitiveParams
    expected: Literal
    path: tuple[np.ndarray, ...]
    q_above: np.ndarray
    q_at: np.ndarray
    descent: tuple[np.ndarray, ...] = ()
    line: tuple[np.ndarray, ...] = ()
    grip: float = 0.0
    opening: float = GRIPPER_MAX_OPENING
    push_direction: tuple[float, float] = (1.0, 0.0)


@dataclass(frozen=True)
class PlanFailure:
    status: Status
    detail: str


def plan_primitive(scene: Scene, params: PrimitiveParams) -> MotionPlan | PlanFailure:
    """Plan a primitive from the scene as it is; the scene is left unchanged."""
    # Checks move the arm: every query below starts from these joints, not from wherever the
    # last check left it.
    q0 = scene.robot.q_in_limits()
    try:
        with scene.robot.preserved():
            if isinstance(params, PickParams):
                return _plan_pick(scene, params, q0)
            if isinstance(params, PlaceParams):
                return _plan_place(scene, params, q0)
            return _plan_push(scene, params, q0)
    except InvalidInputError as e:  # bins out of range, a target that is no surface
        return PlanFailure(Status.INVALID, str(e))


def plan_transit(
    scene: Scene, q_goal: np.ndarray, ignore: tuple[str, ...] = ()
) -> tuple[np.ndarray, ...] | None:
    """A collision-free path of the arm (and what it holds) from where it is to `q_goal`,
    through objects `ignore`d."""
    held = scene.held()
    with scene.robot.preserved():
        q0 = scene.robot.q_in_limits()
        return _path(scene, q0, q_goal, ignore=ignore + (() if held is None else (held,)))


def overlapped(scene: Scene) -> tuple[str, ...]:
    """The objects the arm (and what it holds) stands in where it is, in a model of a belief:
    the arm is truly there, so a belief that puts an object there is wrong, and no path could
    start while it counts as an obstacle. None are named where the arm meets the arena too."""
    held = scene.held()
    objects = [n for n in scene.objects if n != held]
    with scene.robot.preserved():
        q0 = scene.robot.q_in_limits()
        if scene.checker(ignore=objects).collides(q0):
            return ()
        return tuple(
            n for n in objects if scene.checker(ignore=[m for m in objects if m != n]).collides(q0)
        )


def can_pick(scene: Scene, obj: str) -> bool:
    """Whether a pick could take `obj` up from the scene as it is (a dry run)."""
    return isinstance(plan_primitive(scene, PickParams(obj)), MotionPlan)


def _approach(scene: Scene, target: Pose, ignore: tuple[str, ...], seeds):
    """IK for a pose and for the pose APPROACH above it, with a free straight segment between.

    The given seeds first (the rest pose keeps the arm in one well-conditioned elbow-up branch,
    from which approach and push lines stay reachable), then random restarts: the solver
    returns the first configuration that reaches a pose, which may put the elbow in the table.
    """
    above = Pose(
        (target.position[0], target.position[1], target.position[2] + APPROACH),
        target.orientation,
    )
    near = scene.checker(ignore=ignore)
    robot = scene.robot
    tries = [seeds] + [[scene.rng.uniform(robot.lower, robot.upper)] for _ in range(IK_BRANCHES)]
    for i, start in enumerate(tries):
        # A random branch falls back to nothing: the rest pose's answer is known by then.
        q_above = robot.ik(above, scene.rng, seeds=start, restarts=0, rest_fallback=i == 0)
        if q_above is None or near.collides(q_above):
            continue
        q_at = robot.ik(target, scene.rng, seeds=[q_above], restarts=0)
        if q_at is None:
            continue
        descent = _descent(scene, above, target, q_above)
        if descent is None:
            continue
        chain = [q_above, *descent, q_at]
        # q_at is solved from q_above and may land on another branch than the descent's last
        # point: the arm would swing between them through what a pick ignores, its object.
        branch = not scene.plan_rules.descent_branch
        if (branch or np.max(np.abs(q_at - chain[-2])) <= MAX_JOINT_JUMP) and all(
            near.segment_free(a, b) for a, b in zip(chain, chain[1:], strict=False)
        ):
            return q_above, q_at, descent
    return None


def _descent(scene: Scene, above: Pose, target: Pose, q_above: np.ndarray):
    """Joints at the scene's `descent_points` (`sim.plan_rules`) evenly spaced poses strictly
    between `above` and `target`, each solved from the last, or None where one cannot be
    reached without a branch flip."""
    robot, qs = scene.robot, [q_above]
    a, b = np.array(above.position), np.array(target.position)
    points = scene.plan_rules.descent_points
    for k in range(1, points + 1):
        f = k / (points + 1)
        pose = Pose(tuple(a + (b - a) * f), target.orientation)
        q = robot.ik(
            pose, scene.rng, seeds=[qs[-1]], restarts=0, rest_fallback=False, threshold=LINE_IK_TOL
        )
        if q is None or np.max(np.abs(q - qs[-1])) > MAX_JOINT_JUMP:
            return None
        qs.append(q)
    return tuple(qs[1:])


def _path(scene: Scene, q0: np.ndarray, q_goal: np.ndarray, ignore=()):
    # Straight joint motions that collide mostly sweep the hand or the held object through a
    # shelf's front edge on the way to or from its top: up first, across, then down is free.
    # A lifted pose costs an IK call: the goal's is made when first needed, and only once.
    lifted_goal = functools.cache(lambda: _lifted(scene, q_goal))

    def found(*qs: np.ndarray | None) -> list[np.ndarray]:
        return [q for q in qs if q is not None]

    vias = (
        lambda: found(lifted_goal()),
        lambda: found(_lifted(scene, q0), lifted_goal()),
        lambda: [REST],
    )
    path = scene.motion_planner(ignore).plan(q0, q_goal, vias)
    return None if path is None else tuple(path)


def _lifted(scene: Scene, q: np.ndarray) -> np.ndarray | None:
    """The joints that put the hand LIFT higher than at q, in the same orientation."""
    robot = scene.robot
    robot.set_q(q)
    tcp = robot.tcp()
    above = Pose((tcp.position[0], tcp.position[1], tcp.position[2] + LIFT), tcp.orientation)
    return robot.ik(above, scene.rng, seeds=[q], restarts=0, rest_fallback=False)


def _plan_pick(scene: Scene, p: PickParams, q0: np.ndarray) -> MotionPlan | PlanFailure:
    if p.obj not in scene.bodies:
        return PlanFailure(Status.INVALID, f"'{p.obj}' is not in the scene")
    if scene.robot.held_body is not None:
        return PlanFailure(Status.INVALID, f"the gripper already holds '{scene.held()}'")
    t, pose = scene.world.object_type(p.obj), scene.pose(p.obj)
    # Open only a little wider than the object: fully open fingers reach into close neighbours.
    opening = min(GRIPPER_MAX_OPENING, t.grasp_width + PREGRASP_ROOM)
    scene.robot.set_fingers(opening)  # checked as executed
    top = pose.position[2] + t.height / 2
    tip_z = max(top - GRASP_DEPTH, top - t.height + FLOOR_GAP)
    if t.kind is Kind.BOX:
        yaws = [pose.yaw, pose.yaw + math.pi]  # close across the box's narrow (local x) side
    else:
        # Any yaw closes on a can; the hand turned half round is another arm (its last joint
        # spans 5.9 rad), so beside the base, where the first four run out of that joint's
        # range, the other four may not.
        radial = math.atan2(pose.position[1], pose.position[0]) + math.pi / 2
        yaws = [radial + k * math.pi / 4 for k in (0, 1, -1, 2, 4, 3, 5, 6)]
    for yaw in yaws:
        grasp = Pose((pose.position[0], pose.position[1], tip_z + TIP_OFFSET), topdown(yaw))
        found = _approach(scene, grasp, (p.obj,), [REST, q0])
        if found:
            path = _path(scene, q0, found[0])
            if path is None:
                return PlanFailure(Status.NO_PATH, f"no path to above '{p.obj}'")
            return MotionPlan(
                p,
                in_grasp(p.obj),
                path,
                *found,
                grip=max(0.0, t.grasp_width - 0.002),
                opening=opening,
            )
    return PlanFailure(Status.NO_IK, f"no collision-free grasp of '{p.obj}'")


def _plan_place(scene: Scene, p: PlaceParams, q0: np.ndarray) -> MotionPlan | PlanFailure:
    if scene.held() != p.obj:
        return PlanFailure(Status.INVALID, f"'{p.obj}' is not held")
    world = scene.world
    t = world.object_type(p.obj)
    if p.target in world.surface_capacity:
        if p.x_bin is None or p.y_bin is None:
            return PlanFailure(Status.INVALID, f"placing on '{p.target}' needs x and y bins")
        x, y = place_xy(p.obj, p.target, p.x_bin, p.y_bin, world)
        z = world.surface_rect(p.target).z
        # The convention first (long side along y), so the bins' insets hold; turned as needed.
        turns = (0, 2, 1, -1) if t.kind is Kind.BOX else (0, 1, 2, -1, 0.5, -0.5)
        yaws = [place_yaw(p.target, world) + k * math.pi / 2 for k in turns]
    elif p.target in scene.bodies and p.target != p.obj:
        base = scene.pose(p.target)
        x, y = base.position[:2]
        z = base.position[2] + world.object_type(p.target).height / 2
        yaws = [base.yaw + k * math.pi / 2 for k in (0, 1, -1, 2)]
    else:
        return PlanFailure(Status.INVALID, f"'{p.target}' is neither a surface nor another object")
    offset = scene.robot.held_offset
    near = scene.checker(ignore=(p.obj,))
    for yaw in yaws:
        obj_pose = Pose((x, y, z + t.height / 2 + DROP), yaw_quat(yaw))
        # An object that would touch a neighbour where it is let go needs no arm to tell: the
        # approach ends with it there, and inverse kinematics is most of a failed place's time.
        if near.held_collides_at(obj_pose):
            continue
        found = _approach(scene, obj_pose.compose(offset.inverse()), (p.obj,), [REST, q0])
        if found:
            path = _path(scene, q0, found[0], ignore=(p.obj,))
            if path is None:
                return PlanFailure(Status.NO_PATH, f"no path to above the place pose of '{p.obj}'")
            return MotionPlan(p, on(p.obj, p.target), path, *found)
    return PlanFailure(Status.NO_IK, f"no collision-free way to place '{p.obj}' there")


def _plan_push(scene: Scene, p, q0: np.ndarray) -> MotionPlan | PlanFailure:
    if p.obj not in scene.bodies:
        return PlanFailure(Status.INVALID, f"'{p.obj}' is not in the scene")
    if scene.robot.held_body is not None:
        return PlanFailure(Status.INVALID, "the gripper is holding something")
    world = scene.world
    shelf = prepush_shelf(world, scene.pose(p.obj))
    if shelf is None:
        return PlanFailure(Status.INVALID, f"'{p.obj}' is not on a prepush region")
    interior = world.shelves[shelf].interior
    angle, dist = push_values(p.angle_bin, p.dist_bin, interior.yaw)
    u = np.array([math.cos(angle), math.sin(angle), 0.0])
    pose, t = scene.pose(p.obj), world.object_type(p.obj)
    # The object goes at most as far as the fingertips push it, and measured about 4 cm less
    # (arm lag, finger shape). `hsgplan bench push-reach`: of 480 uniformly drawn pushes, and of
    # 1,600 more, every success had this bound at least 2.63 cm past the shelf's front, while
    # under 2.5 cm ~130 of the 1,600 were carried out in vain; one short of that front plus
    # PUSH_SLACK is refused before it is planned and run.
    # (along the shelf's own x: into it)
    reach = interior.to_local(*pose.position[:2])[0] + push_carry(dist) * math.cos(
        angle - interior.yaw
    )
    if reach < interior.x_min + PUSH_SLACK:
        return PlanFailure(Status.EFFECT_NOT_REACHED, f"too short to bring '{p.obj}' into {shelf}")
    orn = tilted(angle, PUSH_PITCH)
    axis = Pose((0, 0, 0), orn).rotation[:, 2]
    start = np.array([*pose.position[:2], min(PUSH_TIP_Z, t.height / 2)])
    tip0 = start - (extent_along(p.obj, pose.yaw, angle, world) + PUSH_LEAD) * u
    tcp = [
        Pose(tuple(tip0 + u * s - TIP_OFFSET * axis), orn)
        for s in np.arange(0.0, dist + 1e-9, PUSH_STEP)
    ]
    robot = scene.robot
    robot.set_fingers(0.0)  # checked as executed: the hand pushes with closed fingers
    if _hand_blocked(scene, p.obj, tcp):
        return PlanFailure(Status.NO_PATH, f"the hand would hit something pushing '{p.obj}'")
    random_seeds = [[scene.rng.uniform(robot.lower, robot.upper)] for _ in range(2)]
    for seeds in [[REST], *random_seeds]:
        found = _approach(scene, tcp[0], (p.obj,), seeds)
        line = found and _line(scene, tcp[1:], found[1])
        if line:
            path = _path(scene, q0, found[0])
            if path is None:
                return PlanFailure(Status.NO_PATH, f"no path to above the push start of '{p.obj}'")
            return MotionPlan(
                p,
                inside(p.obj, shelf),
                path,
                *found,
                line=tuple(line),
                push_direction=(float(u[0]), float(u[1])),
            )
    return PlanFailure(Status.NO_PATH, f"no reachable, collision-free push line for '{p.obj}'")


def _hand_blocked(scene: Scene, obj: str, line: list[Pose]) -> bool:
    """Whether the closed hand touches something where a push needs it: at the start and
    APPROACH above it (the arena and the other objects, with the approach's margin), or along
    the line (the arena: objects there are the push's business). Where the hand is depends on
    the TCP pose alone, so such a push fails from every start of the arm: asked of the hand on
    its own, it costs no inverse kinematics (these were most pushes' planning time)."""
    first = line[0]
    above = Pose((*first.position[:2], first.position[2] + APPROACH), first.orientation)
    hand, near = scene.closed_hand(), scene.obstacles(ignore=(obj,))
    return hand.touches((above, first), near, SAFETY_MARGIN) or hand.touches(
        reversed(line), scene.arena.obstacles, 0.0
    )


def _line(scene: Scene, poses: list[Pose], q_start: np.ndarray) -> list[np.ndarray] | None:
    """Joints along a Cartesian line, one per pose, or None if it leaves the reach or the arm
    collides with the arena.

    Inverse kinematics every LINE_IK_EVERY poses, each seeded by the last, and the joints
    interpolated between: the IK is most of a line's time. Measured over 59 lines
    (`hsgplan bench line-error`): with IK every 4 cm the hand is 0.92 mm from its line pose on
    average and 3.1 mm at most, against 0.83 and 2.9 mm every 2 cm (the rest is the solver's
    tolerance); the same lines were found.
    Every joint value is collision-checked.
    """
    robot, arena = scene.robot, scene.checker(ignore=scene.objects, margin=0.0)
    ends = list(range(LINE_IK_EVERY - 1, len(poses), LINE_IK_EVERY))
    if not ends or ends[-1] != len(poses) - 1:
        ends.append(len(poses) - 1)
    qs, done = [q_start], 0
    for i in ends:
        q0 = qs[-1]
        q = robot.ik(
            poses[i], scene.rng, seeds=[q0], restarts=0, rest_fallback=False, threshold=LINE_IK_TOL
        )
        if q is None or np.max(np.abs(q - q0)) > MAX_JOINT_JUMP:
            return None
        n = i + 1 - done
        for k in range(1, n + 1):
            qk = q if k == n else q0 + (q - q0) * (k / n)
            if arena.collides(qk):
                return None
            qs.append(qk)
        done = i + 1
    return qs[1:]


def prepush_shelf(world: World, pose: Pose) -> str | None:
    """The shelf whose prepush region an object stands on, if any."""
    return world.prepush_shelf(*pose.position[:2])
