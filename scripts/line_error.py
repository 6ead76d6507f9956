"""How far the hand strays from a push line with the line's IK solved every k poses
(LINE_IK_EVERY's basis).

Usage: python scripts/line_error.py [TASKS] [EVERY ...]
Runs TASKS push tasks (default 40) of a seed stream no data uses (seed 41), once per EVERY
(default 4 and 8), and prints one JSON object per EVERY: the lines found and the hand's distance
from each line pose in millimetres (mean, 99th percentile, max). Between solved poses the
joints are interpolated, so the distance is the interpolation's error plus the solver's.
"""

from __future__ import annotations

import json
import sys

import numpy as np

from hsgplan.data.motion_tasks import draw_task
from hsgplan.data.motion_trials import run_task
from hsgplan.domain.parameters import MotionPrimitive
from hsgplan.sim import motion_plans
from hsgplan.sim.scene import Scene

SEED = 41


def measure(tasks: int, every: int) -> dict:
    errors: list[float] = []
    lines = 0
    solve, saved = motion_plans._line, motion_plans.LINE_IK_EVERY

    def watched(scene, poses, q_start):
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
        with Scene((), seed=SEED) as scene:
            for i in range(tasks):
                run_task(scene, draw_task(MotionPrimitive.PUSH, SEED, i))
    finally:
        motion_plans._line, motion_plans.LINE_IK_EVERY = solve, saved
    mm = np.array(errors) * 1000
    return {
        "every": every,
        "lines": lines,
        "mean_mm": round(float(mm.mean()), 3),
        "p99_mm": round(float(np.percentile(mm, 99)), 2),
        "max_mm": round(float(mm.max()), 2),
    }


def main(argv: list[str]) -> int:
    tasks = int(argv[0]) if argv else 40
    for every in [int(a) for a in argv[1:]] or [4, 8]:
        print(json.dumps(measure(tasks, every)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
