"""pick, place and push with the paper's parametrisation, each returning a typed outcome.

Execution replays a `MotionPlan`: the planned transit or transfer path, the straight approach,
the contact phase, and the retreat. The contact phase of a push runs under physics with the arm
position-controlled along the push line; grasps are made firm by a fixed constraint once the
fingers have closed (`Panda.attach`). Nothing here raises for a failed motion: every failure is
an `Outcome` with a `Status`.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from hsgplan.domain.parameters import PickParams, PlaceParams, PrimitiveParams
from hsgplan.domain.world import GRIPPER_MAX_OPENING
from hsgplan.sim.motion import densify
from hsgplan.sim.motion_plans import MotionPlan, PlanFailure, plan_primitive
from hsgplan.sim.outcome import Outcome, verify
from hsgplan.sim.scene import Scene

PUSH_SUBSTEPS = 3  # physics steps per 5 mm of push: 0.4 m/s (see README "Decisions")

Frame = Callable[[], None]


class Watch:
    """`on_frame` with the time it takes kept apart: pictures are no part of a primitive's
    cost (the arm is then moved through every waypoint, which is)."""

    def __init__(self, on_frame: Frame | None) -> None:
        self.on_frame = on_frame
        self.seconds = 0.0
        self.frame = self._frame if on_frame is not None else None

    def _frame(self) -> None:
        start = time.perf_counter()
        self.on_frame()
        self.seconds += time.perf_counter() - start


def execute(
    scene: Scene,
    params: PrimitiveParams,
    on_frame: Frame | None = None,
    plan: MotionPlan | None = None,
) -> Outcome:
    """Plan (unless a plan made for this scene is given) and run one primitive.

    `on_frame` is called along the way, for pictures; the time it takes is not counted in the
    outcome's seconds (the arm is then moved through every waypoint, which is).
    """
    start = time.perf_counter()
    watch = Watch(on_frame)
    before = scene.scene_graph()
    planned = plan if plan is not None else plan_primitive(scene, params)
    if isinstance(planned, PlanFailure):
        return Outcome(planned.status, planned.detail, time.perf_counter() - start)
    run_plan(scene, planned, watch.frame)
    status, detail = verify(scene, before, params.obj, planned.expected)
    return Outcome(status, detail, time.perf_counter() - start - watch.seconds)


def run_plan(scene: Scene, plan: MotionPlan, on_frame: Frame | None = None, blind: bool = False):
    """Run a planned primitive's joint motions in the scene; physics does the rest.

    `blind`: the plan was made in the robot's model of the scene, not in this one (a camera
    observer's belief): a pick then holds whatever body its closed fingers touch, if any,
    rather than the one it was planned for (whose true pose the robot does not know)."""
    if isinstance(plan.params, PickParams):
        _run_pick(scene, plan, on_frame, blind)
    elif isinstance(plan.params, PlaceParams):
        _run_place(scene, plan, on_frame)
    else:
        _run_push(scene, plan, on_frame)


def run_path(scene: Scene, path, on_frame: Frame | None = None) -> None:
    """Move the arm along a planned path (what it holds goes with it)."""
    # Setting joints moves nothing else and steps no physics: unwatched, only the last counts.
    if on_frame is None:
        scene.robot.set_q(path[-1])
        return
    for q in densify(list(path)):
        scene.robot.set_q(q)
        on_frame()


def _run_pick(scene: Scene, plan: MotionPlan, on_frame, blind: bool = False) -> None:
    robot = scene.robot
    robot.set_fingers(plan.opening)
    run_path(scene, plan.path, on_frame)
    run_path(scene, [plan.q_above, plan.q_at], on_frame)
    # The fingers close to the object's width, then a fixed constraint makes the grasp firm.
    robot.set_fingers(plan.grip)
    if not blind:
        robot.attach(scene.bodies[plan.params.obj])
    elif (body := robot.between_fingers(tuple(scene.bodies.values()))) is not None:
        robot.attach(body)
    else:
        robot.set_fingers(0.0)  # closed on nothing
    run_path(scene, [plan.q_at, plan.q_above], on_frame)


def _run_place(scene: Scene, plan: MotionPlan, on_frame) -> None:
    robot = scene.robot
    run_path(scene, plan.path, on_frame)
    run_path(scene, [plan.q_above, plan.q_at], on_frame)
    robot.detach()
    robot.set_fingers(GRIPPER_MAX_OPENING)
    scene.settle()
    run_path(scene, [plan.q_at, plan.q_above], on_frame)


def _run_push(scene: Scene, plan: MotionPlan, on_frame) -> None:
    robot = scene.robot
    robot.set_fingers(0.0)
    run_path(scene, plan.path, on_frame)
    run_path(scene, [plan.q_above, plan.q_at], on_frame)
    # Only the pushed object moves unless it is pushed into another, which that wakes.
    with scene.asleep(awake=[plan.params.obj]):
        for q in plan.line:
            robot.drive_to(q, PUSH_SUBSTEPS)
            if on_frame:
                on_frame()
        # Back out the way it came (joints checked against the shelves while planning; the
        # object is ahead of the fingers now), then up to where the approach began.
        run_path(scene, [robot.q(), *reversed(plan.line), plan.q_at, plan.q_above], on_frame)
        scene.settle()
    robot.set_fingers(GRIPPER_MAX_OPENING)
