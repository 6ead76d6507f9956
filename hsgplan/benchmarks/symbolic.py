"""Fast Downward plan time per problem size: `hsgplan bench symbolic`.

Each size gets its own seeded goals and random start states (as `random_state` draws them),
and every configuration plans the same problems, one after another on one core.
"""

from __future__ import annotations

import random
import statistics
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.world import World
from hsgplan.planning.fast_downward import FastDownwardPlanner, NoPlanError
from hsgplan.symbolic.generator import random_goals, random_state


@dataclass(frozen=True)
class SizeTiming:
    """Medians over the problems of one size for one planner configuration."""

    size: int
    planner: str
    problems: int
    solved: int
    median_seconds: float | None
    median_plan_length: float | None

    def to_json(self) -> dict:
        return asdict(self)


def bench_symbolic(
    sizes: Sequence[int],
    goals: int,
    seed: int,
    world: World,
    optimal_max_size: int = 8,
    timeout_s: float = 30.0,
    on_problem: Callable[[], None] | None = None,
) -> list[SizeTiming]:
    """Time both Fast Downward configurations on `goals` problems per size, in `world`.

    The optimal configuration runs only up to `optimal_max_size` objects: past that, A* with
    LM-cut runs into its time-out on most problems and the median says nothing.
    """
    if goals <= 0:
        raise InvalidInputError(f"--goals {goals}: need at least one goal per size")
    planners = [
        FastDownwardPlanner(optimal=False, timeout_s=timeout_s),
        FastDownwardPlanner(optimal=True, timeout_s=timeout_s),
    ]
    rows = []
    for n in sizes:
        rng = random.Random(f"bench-symbolic-{n}-{seed}")
        problems = [
            (random_state(g.objects, rng, world=world), g)
            for g in random_goals(n, goals, seed, world=world)
        ]
        for planner in planners:
            if planner.optimal and n > optimal_max_size:
                continue
            seconds, lengths = [], []
            for state, goal in problems:
                try:
                    plan = planner.plan(state, goal)
                    seconds.append(plan.seconds)
                    lengths.append(len(plan))
                except NoPlanError:
                    pass
                if on_problem:
                    on_problem()
            rows.append(
                SizeTiming(
                    n,
                    planner.name,
                    len(problems),
                    len(seconds),
                    statistics.median(seconds) if seconds else None,
                    statistics.median(lengths) if lengths else None,
                )
            )
    return rows
