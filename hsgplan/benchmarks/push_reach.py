"""How far past the shelf's front a push's bound lies for the pushes that succeed: `hsgplan bench
push-reach`, the basis of PUSH_SLACK (`sim/motion_plans.py`, docs/decisions.md).

Runs push tasks of the collection's seed-0 stream from a task index far past any shipped data,
(in the kitchen, or task i in the i-th of the worlds given, counted round) with the too-short
refusal switched off, and takes each trial's margin
`x + (dist - PUSH_LEAD) cos(angle) - x_min`: PUSH_SLACK must stay below every success's margin,
and the trials under it are those the refusal spares.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import asdict, dataclass

from hsgplan.data.motion_tasks import draw_task
from hsgplan.data.motion_trials import run_task
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.parameters import PUSH_LEAD, MotionPrimitive, push_values
from hsgplan.domain.scene import World
from hsgplan.sim import motion_plans
from hsgplan.sim.scene import Scene

SEED = 0  # the collection's own stream: the margins are those its pushes meet


@dataclass(frozen=True)
class PushReach:
    trials: int
    successes: int
    smallest_margin_of_a_success_m: float | None
    push_slack_m: float
    trials_under_the_slack: int
    statuses: dict[str, int]

    def to_json(self) -> dict:
        return asdict(self)


def reach_margin(x: float, angle: float, dist: float, x_min: float) -> float:
    """How far past the shelf's front (`x_min`) the fingertips' bound of a push ends."""
    return x + (dist - PUSH_LEAD) * math.cos(angle) - x_min


def summarize(
    margins: Iterable[tuple[float, bool]], statuses: Mapping[str, int], slack: float
) -> PushReach:
    """The report over (margin, succeeded) pairs, one per trial."""
    margins = list(margins)
    ok = [m for m, success in margins if success]
    return PushReach(
        trials=len(margins),
        successes=len(ok),
        smallest_margin_of_a_success_m=round(min(ok), 4) if ok else None,
        push_slack_m=slack,
        trials_under_the_slack=sum(m < slack for m, _ in margins),
        statuses=dict(statuses),
    )


def push_reach(
    tasks: int,
    first: int,
    worlds: Sequence[World],
    on_task: Callable[[], None] | None = None,
) -> PushReach:
    if any(w.goal_interior is None for w in worlds):
        raise InvalidInputError("push-reach: a scene has no shelf interior to push into")
    slack = motion_plans.PUSH_SLACK
    margins: list[tuple[float, bool]] = []
    statuses: Counter[str] = Counter()
    # with the refusal off, the pushes it would refuse are run and their margins seen
    motion_plans.PUSH_SLACK = -math.inf
    try:
        for k, world in enumerate(worlds):  # one physics client a world
            with Scene((), seed=SEED, world=world) as scene:
                for index in range(first + k, first + tasks, len(worlds)):
                    task = draw_task(MotionPrimitive.PUSH, SEED, index, world)
                    for trial in run_task(scene, task) or []:
                        interior = world.shelves[trial.target].interior  # in its frame
                        angle, dist = push_values(*trial.bins)
                        x = interior.to_local(*trial.before.pose(trial.obj).position[:2])[0]
                        margins.append((reach_margin(x, angle, dist, interior.x_min), trial.ok))
                        statuses[trial.status.value] += 1
                    if on_task:
                        on_task()
    finally:
        motion_plans.PUSH_SLACK = slack
    return summarize(margins, statuses, slack)
