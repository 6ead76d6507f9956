"""Self-supervised motion data collection: chunks of trials run by a local process pool or by
Ray, saved as they finish, packed into a dataset of the first N successful trials.

A work folder holds the configuration and one file per finished chunk. A run started again
with the same folder reads which chunks are done and runs only the others, so an interruption
loses at most the chunks that were in flight and repeats nothing that was saved. The dataset is
the successful trials in (task, attempt) order, cut at N: it is the same whichever engine ran
the chunks, in whatever order they finished, and however often the run was interrupted.

Given a folder of scene files (of the same object and fixture types), chunk k is staged in the
folder's k-th file, counted round, as `collect reach` stages state k: one dataset whose rows
each know their world, so that a network learns round many scenes.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from hsgplan.data import motion_store as store
from hsgplan.data.motion_tasks import P_FELL_SHORT
from hsgplan.data.motion_trials import ATTEMPTS_PER_TASK, TASKS_PER_CHUNK, run_chunk
from hsgplan.domain.checks import (
    BOUNDS,
    MAX_SAMPLES,
    MAX_TASKS_PER_CHUNK,
    bounded,
    check_fields,
    setting,
)
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.parameters import MotionPrimitive
from hsgplan.domain.scene import World
from hsgplan.domain.scene_file import read_worlds, scene_file_names
from hsgplan.runner.engines import engine
from hsgplan.runner.run_folder import check_own, claim
from hsgplan.scene_graph.names import names_world

WORK = "work"
REJECTED = "rejected"


@dataclass(frozen=True)
class CollectConfig:
    primitive: MotionPrimitive
    samples: int = field(metadata=bounded(lo=0, hi=MAX_SAMPLES))
    seed: int = setting(0, **BOUNDS["seed"])
    workers: int = setting(2, **BOUNDS["workers"])
    ray_address: str | None = None
    # the unit of work, and of what an interruption loses
    tasks_per_chunk: int = setting(TASKS_PER_CHUNK, lo=1, hi=MAX_TASKS_PER_CHUNK)
    # a scene file, or a folder of them, whose worlds the tasks are drawn and staged in (None:
    # the kitchen)
    scene: str | None = None
    # pushes only: the chance that a task's can starts where a short push left it
    # (`data.motion_tasks.P_FELL_SHORT`)
    fell_short: float = setting(P_FELL_SHORT, lo=0.0, hi=1.0)

    def __post_init__(self) -> None:
        check_fields(self)
        if self.primitive is MotionPrimitive.PLACE and self.fell_short != P_FELL_SHORT:
            raise InvalidInputError("--fell-short sets where pushes start: collect push only")

    def places(self) -> list[tuple[str | None, World]]:
        """The scene files chunks are staged in, in turn, with their worlds (the kitchen's
        none); a bad scene file, or a folder of scenes of other types, refused in one line."""
        if self.scene is None:
            return [(None, names_world())]
        found = read_worlds(self.scene)
        store.one_set_of_types(list(found.values()), self.scene)
        if self.primitive is MotionPrimitive.PUSH:
            for path, world in found.items():
                if world.goal_interior is None:
                    raise InvalidInputError(f"'{path}' has no shelf interior to push into")
        return [(str(path), world) for path, world in found.items()]

    def round_scenes(self) -> bool:
        return self.scene is not None and Path(self.scene).is_dir()

    def dataset_settings(self) -> dict:
        """What decides a dataset's rows, kept in its manifest: the chunking too where chunks
        take turns round a folder of scenes; a kitchen collection records no scene, as before
        scenes could be given."""
        per_chunk = {}
        if self.round_scenes():
            files = scene_file_names(self.scene)
            per_chunk = {"tasks_per_chunk": self.tasks_per_chunk, "scene_files": files}
        return (
            {
                "primitive": self.primitive.value,
                "seed": self.seed,
                "samples": self.samples,
                "attempts_per_task": ATTEMPTS_PER_TASK[self.primitive],
                "schema_version": store.SCHEMA_VERSION,
            }
            | self.scene_setting()
            | self.fell_short_setting()
            | per_chunk
        )

    def fell_short_setting(self) -> dict:
        """The share of short starts as the settings record it: none at the shipped share,
        as before it could be set (so the shipped data's settings stay as they were)."""
        return {} if self.fell_short == P_FELL_SHORT else {"fell_short": self.fell_short}

    def scene_setting(self) -> dict:
        """The scene as the settings record it: none for the kitchen, as before scenes could
        be given (so the shipped data's settings stay as they were)."""
        return {} if self.scene is None else {"scene": self.scene}


@dataclass(frozen=True)
class CollectSummary:
    samples: int  # successful trials in the dataset
    trials: int  # trials run in the chunks the dataset draws on
    chunks_run: int  # chunks this call ran (the rest were on disk)
    unstaged: int
    dataset: Path
    set_aside: int = 0  # damaged or foreign chunk files moved to `rejected/` and run again


def work_folder(out: Path, primitive: MotionPrimitive, seed: int) -> Path:
    return out / WORK / f"{primitive.value}-seed{seed}"


def check_out(config: CollectConfig, out: Path) -> None:
    """Refuse, before anything is written, an output folder that is not a motion dataset
    folder, and a dataset file there made with other settings (or with none recorded: the
    shipped data without its manifest): collections never overwrite data they did not make."""
    if not (out / WORK).is_dir():
        check_own(out, store.SCHEMA, "motion dataset")
    dataset = out / f"{config.primitive.value}.npz"
    if dataset.exists():
        made = store.read_manifest(dataset)
        if made is None or {k: v for k, v in made.items() if k != "sha256"} != (
            config.dataset_settings()
        ):
            where = f", scene {made['scene']}" if made and made.get("scene") else ""
            settings = f"samples {made.get('samples')}, seed {made.get('seed')}" if made else ""
            was = f" ({settings}{where})" if made else ""
            raise InvalidInputError(
                f"'{dataset}' holds a dataset collected with other settings{was}; use another --out"
            )


def _done_chunks(config: CollectConfig, folder: Path, places) -> tuple[dict[int, int], int]:
    """Successful trials in each chunk on disk, and how many files were set aside: a damaged
    chunk, or one that is not the chunk its name says, is moved to `rejected/` (never kept,
    never silently deleted) and runs again."""
    for leftover in folder.glob(".*.tmp*"):
        leftover.unlink()  # a write cut short
    done, rejected = {}, 0
    for k, path in store.chunk_files(folder).items():
        try:
            data, _ = store.load_chunk(
                path, config.primitive, config.seed, k, config.tasks_per_chunk, _of(places, k)[1]
            )
            done[k] = int(data.ok.sum())
        except InvalidInputError:
            (folder / REJECTED).mkdir(exist_ok=True)
            os.replace(path, folder / REJECTED / f"{path.name}.{time.time_ns()}")
            rejected += 1
    return done, rejected


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
    places = config.places()
    check_out(config, out)
    folder = work_folder(out, config.primitive, config.seed)
    claim(
        folder,
        "collect-motion",
        {
            "primitive": config.primitive.value,
            "seed": config.seed,
            "tasks_per_chunk": config.tasks_per_chunk,
            "attempts_per_task": ATTEMPTS_PER_TASK[config.primitive],
            "schema_version": store.SCHEMA_VERSION,
            "chunk_format": store.CHUNK_FORMAT,
        }
        | config.scene_setting()
        | config.fell_short_setting()
        | {k: v for k, v in config.dataset_settings().items() if k == "scene_files"},
        f"'{folder}' holds chunks made with other collection settings; use another --out",
    )
    store.write_schema(out, places[0][1])
    done, rejected = _done_chunks(config, folder, places)
    ran = 0
    if progress:
        progress(sum(done.values()))
    if _prefix_done(done, config.samples) is None:
        with engine(config.workers, config.ray_address) as runner:
            ran = _run(runner, config, folder, done, progress, places)
    return _pack(config, out, folder, done, ran, rejected, places)


def _of(places: list[tuple[str | None, World]], chunk: int) -> tuple[str | None, World]:
    """The scene file and world chunk `chunk` is staged in."""
    return places[chunk % len(places)]


def _run(
    runner, config: CollectConfig, folder: Path, done: dict[int, int], progress, places
) -> int:
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
            scene_file = _of(places, nxt)[0]
            job = (
                config.primitive.value,
                config.seed,
                nxt,
                config.tasks_per_chunk,
                scene_file,
                config.fell_short,
            )
            in_flight[runner.submit(run_chunk, *job)] = nxt
            expected += per_chunk
        handle, result = runner.next_done(set(in_flight))
        del in_flight[handle]
        store.save_chunk(folder, result, _of(places, result.chunk)[1])
        done[result.chunk] = sum(t.ok for t in result.trials)
        ran += 1
        if progress:
            progress(sum(done.values()))
    return ran


def _pack(
    config: CollectConfig, out: Path, folder: Path, done, ran: int, rejected: int, places
) -> CollectSummary:
    n_chunks = _prefix_done(done, config.samples) or 0
    kind, seed, per_chunk = config.primitive, config.seed, config.tasks_per_chunk
    chunks = [
        store.load_chunk(store.chunk_path(folder, k), kind, seed, k, per_chunk, _of(places, k)[1])
        for k in range(n_chunks)
    ]
    unstaged = sum(u for _, u in chunks)
    trials = store.concat(config.primitive, [data for data, _ in chunks], places[0][1])
    order = np.lexsort((trials.attempt, trials.task))
    ok = order[trials.ok[order]][: config.samples]
    dataset = out / f"{config.primitive.value}.npz"
    store.save(dataset, trials.take(ok))
    store.write_manifest(dataset, config.dataset_settings())
    # Every trial up to the last sample, failures included: what a success classifier learns from.
    upto = order[: int(np.flatnonzero(order == ok[-1])[0]) + 1] if len(ok) else ok
    every = out / f"{config.primitive.value}_trials.npz"
    store.save(every, trials.take(upto))
    store.write_manifest(every, config.dataset_settings())
    return CollectSummary(len(ok), len(trials), ran, unstaged, dataset, rejected)
