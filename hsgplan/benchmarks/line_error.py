"""How far the hand strays from a push line with the line's IK solved every k poses: `hsgplan
bench line-error`, the basis of LINE_IK_EVERY (`sim/motion_plans.py`, docs/decisions.md).

Runs push tasks of a seed stream no data uses (in the kitchen, or task i in the i-th of the
worlds given, counted round), once per k, and measures the hand's distance from
every pose of each line found. Between solved poses the joints are interpolated, so the
distance is the interpolation's error plus the solver's.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass

import numpy as np

from hsgplan.data.motion_tasks import draw_task
from hsgplan.data.motion_trials import run_task
from hsgplan.domain.parameters import MotionPrimitive
from hsgplan.domain.scene import World
from hsgplan.sim import motion_plans
from hsgplan.sim.scene import Scene

SEED = 41  # no collection draws from it


@dataclass(frozen=True)
class LineError:
    every: int
    lines: int
    mean_mm: float | None
    p99_mm: float | None
    max_mm: float | None

    def to_json(self) -> dict:
        return asdict(self)


def summarize(every: int, lines: int, errors_m: Sequence[float]) -> LineError:
    """The report over the hand's distances (m) from its line poses; no line, no distances."""
    if not len(errors_m):
        return LineError(every, lines, None, None, None)
    mm = np.asarray(errors_m, dtype=float) * 1000
    return LineError(
        every,
        lines,
        round(float(mm.mean()), 3),
        round(float(np.percentile(mm, 99)), 2),
        round(float(mm.max()), 2),
    )


def line_error(
    tasks: int,
    every: int,
    worlds: Sequence[World],
    on_task: Callable[[], None] | None = None,
) -> LineError:
    errors: list[float] = []
    lines = 0
    solve, saved = motion_plans._line, motion_plans.LINE_IK_EVERY

    def watched(scene, poses, q_start):
        # the planner's own line solver, its joints replayed against the poses asked for
        nonlocal lines
        qs = solve(scene, poses, q_start)
        if qs is not None:
            lines += 1
            with scene.robot.preserved():
                for q, pose in zip(qs, poses, strict=True):
                    scene.robot.set_q(q)
                    errors.append(scene.robot.tcp().distance(pose))
        return qs

    motion_plans._line, motion_plans.LINE_IK_EVERY = watched, every
    try:
        for k, world in enumerate(worlds):  # one physics client a world
            with Scene((), seed=SEED, world=world) as scene:
                for i in range(k, tasks, len(worlds)):
                    run_task(scene, draw_task(MotionPrimitive.PUSH, SEED, i, world))
                    if on_task:
                        on_task()
    finally:
        motion_plans._line, motion_plans.LINE_IK_EVERY = solve, saved
    return summarize(every, lines, errors)
