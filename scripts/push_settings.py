"""Push successes and time per success under other push speeds and tries per staged scene
(the basis of PUSH_SUBSTEPS and ATTEMPTS_PER_TASK[push]).

Usage: python scripts/push_settings.py [SCENES] [TRIALS] [SUBSTEPS:ATTEMPTS ...]
For each setting (default 4:4 3:4 3:8), runs push tasks of a seed stream no data uses (seeds
300.., SCENES physics clients, default 4) until each client has tried TRIALS parameter pairs
(default 192), and prints one JSON object: trials, successes, and CPU seconds per success
(process time: less sensitive to a shared machine than wall time, still noisy by ~10%).
"""

from __future__ import annotations

import json
import sys
import time

from hsgplan.data import motion_trials
from hsgplan.data.motion_tasks import draw_task
from hsgplan.domain.parameters import MotionPrimitive
from hsgplan.sim import primitives
from hsgplan.sim.scene import Scene

FIRST_SEED = 300
PUSH = MotionPrimitive.PUSH


def measure(scenes: int, trials: int, substeps: int, attempts: int) -> dict:
    saved = primitives.PUSH_SUBSTEPS, motion_trials.ATTEMPTS_PER_TASK[PUSH]
    primitives.PUSH_SUBSTEPS, motion_trials.ATTEMPTS_PER_TASK[PUSH] = substeps, attempts
    ran = successes = 0
    start = time.process_time()
    try:
        for seed in range(FIRST_SEED, FIRST_SEED + scenes):
            with Scene((), seed=seed) as scene:
                for index in range(trials // attempts):
                    got = motion_trials.run_task(scene, draw_task(PUSH, seed, index)) or []
                    ran += len(got)
                    successes += sum(t.ok for t in got)
    finally:
        primitives.PUSH_SUBSTEPS, motion_trials.ATTEMPTS_PER_TASK[PUSH] = saved
    seconds = time.process_time() - start
    return {
        "substeps": substeps,
        "attempts": attempts,
        "trials": ran,
        "successes": successes,
        "cpu_s_per_success": round(seconds / max(1, successes), 3),
    }


def main(argv: list[str]) -> int:
    scenes = int(argv[0]) if argv else 4
    trials = int(argv[1]) if len(argv) > 1 else 192
    settings = argv[2:] or ["4:4", "3:4", "3:8"]
    for s in settings:
        substeps, attempts = (int(v) for v in s.split(":"))
        print(json.dumps(measure(scenes, trials, substeps, attempts)), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
