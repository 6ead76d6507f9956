"""Seconds per primitive (planning included) and per oracle episode: `hsgplan bench sim`.

Episodes run one after another in this process (one core), on the evaluation protocol's goals,
in the kitchen or in a scene file's world (each file of a folder, with the same goal seeds).
"""

from __future__ import annotations

import statistics
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

from hsgplan.agents.registry import make_agent
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.scene_file import default_world
from hsgplan.evaluation.config import EvalConfig, world_of_file
from hsgplan.evaluation.episode import EpisodeRecord, run_episode
from hsgplan.evaluation.protocol import episode_specs
from hsgplan.sim.env import KitchenStorageEnv

PRIMITIVES = ("pick", "place", "push")


@dataclass(frozen=True)
class SimTiming:
    what: str
    samples: int
    median_seconds: float | None


def bench_sim(
    sizes: Sequence[int],
    episodes: int,
    seed: int,
    on_episode: Callable[[EpisodeRecord], None] | None = None,
    scene: str | None = None,
) -> list[SimTiming]:
    if episodes <= 0:
        raise InvalidInputError(f"--episodes {episodes}: need at least one episode per size")
    specs = episode_specs(EvalConfig("oracle", tuple(sizes), episodes, seed, scene=scene))
    records = []
    for spec in specs:
        world = default_world() if spec.scene is None else world_of_file(spec.scene)
        record = run_episode(
            KitchenStorageEnv(visuals=False, world=world),
            make_agent("oracle"),
            parse_goal(spec.goal, world=world),
            spec.seed,
        )
        records.append(replace(record, scene=spec.scene))
        if on_episode:
            on_episode(records[-1])
    rows = []
    for kind in PRIMITIVES:
        times = [
            s.execution_seconds
            for r in records
            for s in r.steps
            if s.action.startswith(kind) and s.status == "success"
        ]
        rows.append(
            SimTiming(
                f"{kind} (successful, planning included)",
                len(times),
                statistics.median(times) if times else None,
            )
        )
    for n in sizes:
        times = [r.seconds for r in records if r.size == n]
        rows.append(SimTiming(f"oracle episode, {n} objects", len(times), statistics.median(times)))
    return rows
