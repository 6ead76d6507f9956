"""Collection throughput: `hsgplan bench collect`.

Collects a fresh dataset of each primitive into a temporary folder with the collector as users
run it (process pool, `workers` processes, start-up included) and reports successful samples
per second of wall time. Uses a seed stream of its own, so it never touches real data.
"""

from __future__ import annotations

import tempfile
import time
from dataclasses import asdict, dataclass
from pathlib import Path

from hsgplan.collect.motion import CollectConfig, collect
from hsgplan.domain.parameters import MotionPrimitive

BENCH_SEED = 777


@dataclass(frozen=True)
class CollectTiming:
    primitive: str
    workers: int
    samples: int
    trials: int
    seconds: float

    @property
    def samples_per_second(self) -> float:
        return self.samples / self.seconds

    def to_json(self) -> dict:
        return asdict(self) | {"samples_per_second": self.samples_per_second}


def bench_collect(
    primitives: list[str], samples: int, workers: int, scene: str | None = None
) -> list[CollectTiming]:
    """Each primitive's collection timed, in the kitchen or in a scene file's world."""
    rows = []
    for p in primitives:
        config = CollectConfig(MotionPrimitive(p), samples, BENCH_SEED, workers, scene=scene)
        with tempfile.TemporaryDirectory() as tmp:
            start = time.perf_counter()
            summary = collect(config, Path(tmp))
            seconds = time.perf_counter() - start
        rows.append(CollectTiming(p, workers, summary.samples, summary.trials, seconds))
    return rows
