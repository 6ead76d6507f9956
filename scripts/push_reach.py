"""How far past the shelf's front the push bound lies for pushes that succeed (PUSH_SLACK's basis).

Usage: python scripts/push_reach.py [TASKS] [FIRST]
Runs TASKS push tasks of the collection's seed-0 stream from index FIRST (defaults 120 and
900000, far past any shipped data) with the too-short refusal switched off, and prints one JSON
object: trials, successes, and the smallest margin `x + (dist - PUSH_LEAD) cos(angle) - x_min`
among successes (PUSH_SLACK must stay below it), with how many trials fall under the slack.
"""

from __future__ import annotations

import json
import math
import sys
from collections import Counter

from hsgplan.data.motion_tasks import draw_task
from hsgplan.data.motion_trials import run_task
from hsgplan.domain.parameters import PUSH_LEAD, MotionPrimitive, push_values
from hsgplan.domain.world import SHELVES
from hsgplan.sim import motion_plans
from hsgplan.sim.scene import Scene


def main(argv: list[str]) -> int:
    tasks = int(argv[0]) if argv else 120
    first = int(argv[1]) if len(argv) > 1 else 900_000
    slack, motion_plans.PUSH_SLACK = motion_plans.PUSH_SLACK, -math.inf
    margins: list[tuple[float, bool]] = []
    statuses: Counter[str] = Counter()
    with Scene((), seed=0) as scene:
        for index in range(first, first + tasks):
            for trial in run_task(scene, draw_task(MotionPrimitive.PUSH, 0, index)) or []:
                angle, dist = push_values(*trial.bins)
                x = trial.before.pose(trial.obj).position[0]
                x_min = SHELVES[trial.target].interior.x_min
                margins.append((x + (dist - PUSH_LEAD) * math.cos(angle) - x_min, trial.ok))
                statuses[trial.status.value] += 1
    ok = [m for m, success in margins if success]
    report = {
        "trials": len(margins),
        "successes": len(ok),
        "smallest_margin_of_a_success_m": round(min(ok), 4) if ok else None,
        "push_slack_m": slack,
        "trials_under_the_slack": sum(m < slack for m, _ in margins),
        "statuses": dict(statuses),
    }
    print(json.dumps(report, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
