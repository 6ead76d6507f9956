"""The evaluation protocol: which episodes an `eval` runs, running them, and what they sum to.

Goals come from the seeded generator (`goals` per size; the paper leaves stacking out of
2-object goals, since its demonstrations cover them) or from a goal file. Each episode's seed
is derived from the run's seed, the size and the goal's index, so any episode can be rerun
alone. Finished episodes are appended to `episodes.jsonl` in the run folder as they finish: an
interrupted run, started again with the same command, skips what is done.
"""

from __future__ import annotations

import statistics
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from functools import partial
from pathlib import Path

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.goals import Goal, parse_goal, read_goal_file
from hsgplan.evaluation.episode import EpisodeRecord
from hsgplan.runner.items import run_items
from hsgplan.symbolic.generator import random_goals


@dataclass(frozen=True)
class EvalConfig:
    agent: str
    sizes: tuple[int, ...]
    goals: int
    seed: int
    goals_file: str | None = None

    def run_name(self) -> str:
        source = Path(self.goals_file).stem if self.goals_file else f"g{self.goals}"
        sizes = "-".join(map(str, self.sizes))
        return f"eval-{self.agent}-s{sizes}-{source}-seed{self.seed}"


@dataclass(frozen=True)
class EpisodeSpec:
    size: int
    index: int
    goal: str
    seed: int

    @property
    def key(self) -> str:
        return f"{self.size}/{self.index}/{self.seed}/{self.goal}"


def episode_specs(config: EvalConfig) -> list[EpisodeSpec]:
    if config.goals < 0:
        raise InvalidInputError(f"--goals {config.goals}: the number of goals cannot be negative")
    by_size: dict[int, list[Goal]] = {}
    if config.goals_file:
        for g in read_goal_file(Path(config.goals_file)):
            by_size.setdefault(g.size, []).append(g)
        by_size = {n: gs for n, gs in by_size.items() if n in config.sizes}
        if not by_size:
            raise InvalidInputError(f"'{config.goals_file}' holds no goal of the sizes asked for")
    else:
        for n in config.sizes:
            by_size[n] = random_goals(n, config.goals, config.seed, stacking=n > 2)
    return [
        EpisodeSpec(n, i, str(g), episode_seed(config.seed, n, i))
        for n in sorted(by_size)
        for i, g in enumerate(by_size[n])
    ]


def episode_seed(seed: int, size: int, index: int) -> int:
    return (seed * 1_000_003 + size * 10_007 + index) % (2**31)


def run_spec(agent_name: str, spec: EpisodeSpec) -> dict:
    """One episode in this process (a worker): its record as JSON."""
    from hsgplan.agents.registry import make_agent
    from hsgplan.evaluation.episode import run_episode
    from hsgplan.sim.env import KitchenStorageEnv

    record = run_episode(
        KitchenStorageEnv(), make_agent(agent_name), parse_goal(spec.goal), spec.seed
    )
    return record.to_json()


def run_evaluation(
    config: EvalConfig,
    run_dir: Path | None,
    workers: int = 2,
    on_episode: Callable[[EpisodeRecord], None] | None = None,
    ray: str | None = None,
) -> list[EpisodeRecord]:
    """Run every episode not yet in `run_dir`, `workers` at a time; all records, in order."""
    specs = episode_specs(config)
    rows = run_items(
        partial(run_spec, config.agent),
        specs,
        key=lambda s: s.key,
        run_dir=run_dir,
        config=asdict(config) | {"sizes": list(config.sizes)},
        workers=workers,
        ray=ray,
        on_result=on_episode and (lambda row: on_episode(EpisodeRecord.from_json(row))),
    )
    return [EpisodeRecord.from_json(row) for row in rows]


def summarize(records: Sequence[EpisodeRecord]) -> dict:
    """`{"by_size": {"2": {"success_rate", "subgoal_completion", "episodes", ...}, ...}}`."""
    by_size: dict[str, dict] = {}
    for n in sorted({r.size for r in records}):
        rs = [r for r in records if r.size == n]
        by_size[str(n)] = {
            "success_rate": sum(r.success for r in rs) / len(rs),
            "subgoal_completion": sum(r.subgoal_completion for r in rs) / len(rs),
            "episodes": len(rs),
            "failures": dict(Counter(r.failure for r in rs if r.failure)),
            "median_steps": statistics.median(len(r.steps) for r in rs),
            "median_seconds": statistics.median(r.seconds for r in rs),
        }
    return {"by_size": by_size}
