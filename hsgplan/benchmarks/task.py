"""Task-planning time, learned regression against Fast Downward: `hsgplan bench task`.

Every planner meets the same problems (seeded goals, start states as `random_state` draws
them) in the symbolic closed loop, one after another on one core (one torch thread):
- `regression`: the learned planner, one decision per step;
- `fd (closed loop)`: Fast Downward replanning from every state, as the learned planner does;
- `fd (one plan)`: Fast Downward planning once per episode, its plan then followed blindly,
  the cheapest way a search-based planner can be used (and the paper's Table 2 comparison).
An episode's time is the sum of its decisions' times; only task planning is timed.
"""

from __future__ import annotations

import random
import statistics
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.world import World
from hsgplan.evaluation.task_eval import run_task_episode
from hsgplan.symbolic.generator import random_goals, random_state


@dataclass(frozen=True)
class TaskTiming:
    """Medians over one size's problems for one planner."""

    size: int
    planner: str
    episodes: int
    solved: int
    median_ms_per_decision: float | None
    median_ms_per_episode: float | None

    def to_json(self) -> dict:
        return asdict(self)


def _row(size: int, planner: str, per_episode: list[list[float]], solved: int) -> TaskTiming:
    decisions = [t for ts in per_episode for t in ts]
    return TaskTiming(
        size,
        planner,
        len(per_episode),
        solved,
        statistics.median(decisions) if decisions else None,
        statistics.median(sum(ts) for ts in per_episode) if per_episode else None,
    )


def bench_task(
    checkpoint: Path,
    sizes: Sequence[int],
    goals: int,
    seed: int,
    world: World,
    on_episode: Callable[[], None] | None = None,
) -> list[TaskTiming]:
    """Time the three planners on `goals` problems per size, in `world`."""
    import torch

    from hsgplan.planning.fast_downward import FastDownwardTaskPlanner, NoPlanError
    from hsgplan.planning.regression.planner import RegressionPlanner

    if goals <= 0:
        raise InvalidInputError(f"--goals {goals}: need at least one goal per size")
    torch.set_num_threads(1)
    learned = RegressionPlanner(checkpoint, seed=seed)
    closed_loop = FastDownwardTaskPlanner(follow_plan=False)
    rows = []
    for n in sizes:
        problems = random_goals(n, goals, seed, stacking=n > 2, world=world)
        times: dict[str, list[list[float]]] = {"regression": [], "fd (closed loop)": []}
        solved = {"regression": 0, "fd (closed loop)": 0, "fd (one plan)": 0}
        plans = []
        for i, goal in enumerate(problems):
            episode_seed = seed * 1000 + i
            for name, planner in (("regression", learned), ("fd (closed loop)", closed_loop)):
                episode = run_task_episode(planner, goal, episode_seed, 0)
                times[name].append(list(episode.decision_ms))
                solved[name] += episode.success
            state = random_state(goal.objects, random.Random(f"task-{episode_seed}"), world=world)
            try:
                plans.append([1000 * closed_loop.planner.plan(state, goal).seconds])
                solved["fd (one plan)"] += 1
            except NoPlanError:
                plans.append([])
            if on_episode:
                on_episode()
        rows += [_row(n, name, ts, solved[name]) for name, ts in times.items()]
        rows.append(_row(n, "fd (one plan)", plans, solved["fd (one plan)"]))
    return rows
