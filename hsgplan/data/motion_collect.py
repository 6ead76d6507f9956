"""Self-supervised motion data collection: chunks of trials run by a local process pool or by
Ray, saved as they finish, packed into a dataset of the first N successful trials.

A work folder holds the configuration and one file per finished chunk. A run started again
with the same folder reads which chunks are done and runs only the others, so an interruption
loses at most the chunks that were in flight and repeats nothing that was saved. The dataset is
the successful trials in (task, attempt) order, cut at N: it is the same whichever engine ran
the chunks, in whatever order they finished, and however often the run was interrupted.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hsgplan.data import motion_store as store
from hsgplan.data.motion_trials import ATTEMPTS_PER_TASK, TASKS_PER_CHUNK, run_chunk
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.parameters import MotionPrimitive
from hsgplan.runner.engines import engine
from hsgplan.runner.run_folder import claim

WORK = "work"


@dataclass(frozen=True)
class CollectConfig:
    primitive: MotionPrimitive
    samples: int
    seed: int = 0
    workers: int = 2
    ray_address: str | None = None
    tasks_per_chunk: int = TASKS_PER_CHUNK  # the unit of work, and of what an interruption loses

    def __post_init__(self) -> None:
        if self.samples < 0:
            raise InvalidInputError(f"--samples {self.samples}: cannot be negative")
        if self.workers < 1:
            raise InvalidInputError(f"--workers {self.workers}: at least one is needed")
        if self.tasks_per_chunk < 1:
            raise InvalidInputError(f"tasks per chunk {self.tasks_per_chunk}: at least one")


@dataclass(frozen=True)
class CollectSummary:
    samples: int  # successful trials in the dataset
    trials: int  # trials run in the chunks the dataset draws on
    chunks_run: int  # chunks this call ran (the rest were on disk)
    unstaged: int
    dataset: Path


def work_folder(out: Path, primitive: MotionPrimitive, seed: int) -> Path:
    return out / WORK / f"{primitive.value}-seed{seed}"


def _done_chunks(folder: Path) -> dict[int, int]:
    """Successful trials in each chunk on disk; a damaged chunk file is removed (it runs again)."""
    done = {}
    for path in sorted(folder.glob("chunk-*.npz")):
        try:
            done[int(path.stem.split("-")[1])] = int(store.load(path).ok.sum())
        except InvalidInputError:
            path.unlink()
    return done


def _prefix_done(done: dict[int, int], samples: int) -> int | None:
    """How many chunks from the first hold `samples` successes, if the ones on disk do."""
    total, k = 0, 0
    while total < samples:
        if k not in done:
            return None
        total += done[k]
        k += 1
    return k


def collect(
    config: CollectConfig, out: Path, progress: Callable[[int], None] | None = None
) -> CollectSummary:
    """Run chunks until the first chunks hold `samples` successes, then write the dataset.

    `progress` is told the number of successes on disk after every finished chunk.
    """
    folder = work_folder(out, config.primitive, config.seed)
    claim(
        folder,
        {
            "primitive": config.primitive.value,
            "seed": config.seed,
            "tasks_per_chunk": config.tasks_per_chunk,
            "attempts_per_task": ATTEMPTS_PER_TASK[config.primitive],
            "schema_version": store.SCHEMA_VERSION,
        },
        f"'{folder}' holds chunks made with other collection settings; use another --out",
    )
    done = _done_chunks(folder)
    ran = 0
    if progress:
        progress(sum(done.values()))
    if _prefix_done(done, config.samples) is None:
        with engine(config.workers, config.ray_address) as runner:
            ran = _run(runner, config, folder, done, progress)
    return _pack(config, out, folder, done, ran)


def _run(runner, config: CollectConfig, folder: Path, done: dict[int, int], progress) -> int:
    in_flight: dict[object, int] = {}
    window = 2 * config.workers
    ran = 0
    while _prefix_done(done, config.samples) is None:
        per_chunk = max(1.0, sum(done.values()) / max(1, len(done)))
        expected = sum(done.values()) + per_chunk * len(in_flight)
        nxt = 0
        while len(in_flight) < window and (expected < config.samples or not in_flight):
            while nxt in done or nxt in in_flight.values():
                nxt += 1
            job = (config.primitive.value, config.seed, nxt, config.tasks_per_chunk)
            in_flight[runner.submit(run_chunk, *job)] = nxt
            expected += per_chunk
        handle, result = runner.next_done(set(in_flight))
        del in_flight[handle]
        store.save_chunk(folder, result)
        done[result.chunk] = sum(t.ok for t in result.trials)
        ran += 1
        if progress:
            progress(sum(done.values()))
    return ran


def _pack(config: CollectConfig, out: Path, folder: Path, done, ran: int) -> CollectSummary:
    n_chunks = _prefix_done(done, config.samples) or 0
    parts = [store.load(store.chunk_path(folder, k)) for k in range(n_chunks)]
    unstaged = sum(store.unstaged_of(store.chunk_path(folder, k)) for k in range(n_chunks))
    trials = store.concat(config.primitive, parts)
    order = np.lexsort((trials.attempt, trials.task))
    ok = order[trials.ok[order]][: config.samples]
    dataset = out / f"{config.primitive.value}.npz"
    store.save(dataset, trials.take(ok))
    # Every trial up to the last sample, failures included: what a success classifier learns from.
    upto = order[: int(np.flatnonzero(order == ok[-1])[0]) + 1] if len(ok) else ok
    store.save(out / f"{config.primitive.value}_trials.npz", trials.take(upto))
    store.write_schema(out)
    return CollectSummary(len(ok), len(trials), ran, unstaged, dataset)
