"""pick, place and push with the paper's parametrisation, each returning a typed outcome.

Execution replays a `MotionPlan` under physics (`sim.actuation`): the planned transit or
transfer path, the straight approach, the contact phase, and the retreat, every one driven by
joint position control with the simulation stepped, so the arm and what it holds push, topple
or are stopped by what they meet. A pick closes the fingers until they stop and holds what they
hold; a push drives the hand along its line. Nothing here raises for a failed motion: every
failure is an `Outcome` with a `Status`.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from hsgplan.domain.parameters import PickParams, PlaceParams, PrimitiveParams
from hsgplan.domain.world import GRIPPER_MAX_OPENING
from hsgplan.sim.actuation import (
    body_in_grasp,
    drive_fingers,
    drive_path,
    press_towards,
    rests_in_hand,
)
from hsgplan.sim.motion_plans import MotionPlan, PlanFailure, plan_primitive
from hsgplan.sim.outcome import Outcome, judge
from hsgplan.sim.scene import TIME_STEP, Scene

PUSH_SUBSTEPS = 3  # physics steps per 5 mm of push: 0.4 m/s (docs/decisions.md)

Frame = Callable[[], None]
# Called with a phase's name as each phase of a primitive ends: "path" (the transit or transfer
# path), "approach" (the straight final approach), "grasp", "release" or "push" (the contact),
# "retreat". What moved in which phase is the episode record's (`sim.outcome.disturbances`).
Phase = Callable[[str], None]


def _untold(name: str) -> None:
    """The `Phase` of a caller that records no phases."""


class Watch:
    """`on_frame` with the time it takes kept apart: pictures are no part of a primitive's
    cost."""

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
    plan: MotionPlan | PlanFailure | None = None,
    on_phase: Phase = _untold,
) -> Outcome:
    """Plan (unless a plan made for this scene, or its failure, is given) and run one
    primitive.

    `on_frame` is called along the way, for pictures; the time it takes is not counted in the
    outcome's seconds. `on_phase` is told as each phase ends (`Phase`).
    """
    start = time.perf_counter()
    watch = Watch(on_frame)
    before = scene.scene_graph()
    planned = plan if plan is not None else plan_primitive(scene, params)
    if isinstance(planned, PlanFailure):
        return Outcome(planned.status, planned.detail, time.perf_counter() - start)
    stopped = run_plan(scene, planned, watch.frame, on_phase)
    verdict = judge(before, scene.scene_graph(), params.obj, planned.expected, stopped)
    return Outcome(verdict.status, verdict.detail, time.perf_counter() - start - watch.seconds)


def run_plan(
    scene: Scene, plan: MotionPlan, on_frame: Frame | None = None, on_phase: Phase = _untold
) -> str | None:
    """Run a planned primitive's joint motions in the scene under physics, telling `on_phase`
    as each phase ends.

    The plan may have been made in the robot's model of the scene rather than in this one (a
    camera observer's belief): a pick holds whatever its closing fingers hold, if anything.
    Returns None, or why the arm was stopped short of where the plan took it.

    Objects at rest sleep meanwhile, which costs the solver nothing (measured: 6 resting
    objects quadruple a physics step), until something touches them, which wakes them."""
    held = scene.held()
    with scene.asleep(awake=() if held is None else (held,)):
        if isinstance(plan.params, PickParams):
            stopped = _run_pick(scene, plan, on_frame, on_phase)
        elif isinstance(plan.params, PlaceParams):
            stopped = _run_place(scene, plan, on_frame, on_phase)
        else:
            stopped = _run_push(scene, plan, on_frame, on_phase)
    scene.feel_hold()
    return stopped


def run_path(scene: Scene, path, on_frame: Frame | None = None) -> bool:
    """Drive the arm along a planned path under physics (what it holds goes with it);
    whether it got to the end."""
    return drive_path(scene.robot, path, TIME_STEP, on_frame).reached


def _approach(scene: Scene, plan: MotionPlan, on_frame, on_phase) -> str | None:
    reached = run_path(scene, plan.path, on_frame)
    on_phase("path")
    if not reached:
        return "the arm was stopped on its way by something it met"
    down = [scene.robot.q(), plan.q_above, *plan.descent, plan.q_at]
    reached = run_path(scene, down, on_frame)
    on_phase("approach")
    if not reached:
        return "the arm was stopped on its final approach by something it met"
    return None


def _retreat(scene: Scene, plan: MotionPlan, on_frame, on_phase) -> str | None:
    up = [scene.robot.q(), *reversed(plan.descent), plan.q_above]
    reached = run_path(scene, up, on_frame)
    on_phase("retreat")
    if not reached:
        return "the arm was stopped on its retreat by something it met"
    return None


def _run_pick(scene: Scene, plan: MotionPlan, on_frame, on_phase) -> str | None:
    robot = scene.robot
    drive_fingers(robot, plan.opening)
    if stopped := _approach(scene, plan, on_frame, on_phase):
        _retreat(scene, plan, on_frame, on_phase)  # the fingers stay open: nothing is taken up
        return stopped
    # The fingers close until they stop; what they hold from opposite sides is held.
    drive_fingers(robot, 0.0)
    if (body := body_in_grasp(robot, tuple(scene.bodies.values()))) is not None:
        robot.attach(body)
    on_phase("grasp")
    stopped = _retreat(scene, plan, on_frame, on_phase)
    if robot.held_body is None:
        # no constraint was made (the fingers met no opposite faces), yet what rose with the
        # hand, resting in it alone, is held by friction: held all the same
        lifted = (b for b in scene.bodies.values() if rests_in_hand(robot, b))
        if (body := next(lifted, None)) is not None:
            robot.carry(body)
    return stopped


def _run_place(scene: Scene, plan: MotionPlan, on_frame, on_phase) -> str | None:
    robot = scene.robot
    if stopped := _approach(scene, plan, on_frame, on_phase):
        return stopped
    robot.detach()
    drive_fingers(robot, GRIPPER_MAX_OPENING)
    scene.settle()
    on_phase("release")
    return _retreat(scene, plan, on_frame, on_phase)


def _run_push(scene: Scene, plan: MotionPlan, on_frame, on_phase) -> str | None:
    robot = scene.robot
    drive_fingers(robot, 0.0)
    if stopped := _approach(scene, plan, on_frame, on_phase):
        return stopped
    for q in plan.line:
        press_towards(robot, q, PUSH_SUBSTEPS)
        if on_frame:
            on_frame()
    on_phase("push")
    # Back out the way it came (joints checked against the shelves while planning; the
    # object is ahead of the fingers now), then up to where the approach began: from the
    # line's point the hand got to, since it lags behind the line's end and catching up
    # would strike the object (measured: a can struck at 1.3 m/s slid to the shelf's back).
    q = robot.q()
    reached = int(np.argmin([np.max(np.abs(p - q)) for p in plan.line]))
    line = plan.line[: reached + 1]
    back = [q, *reversed(line), plan.q_at, *reversed(plan.descent), plan.q_above]
    stopped = None if run_path(scene, back, on_frame) else "stopped backing out of a push"
    scene.settle()
    drive_fingers(robot, GRIPPER_MAX_OPENING)
    on_phase("retreat")
    return stopped
