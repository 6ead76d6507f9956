"""Trainings: one configuration trained with several seeds, a folder each.

`hsgplan train task|motion --seeds K --out DIR` trains the configuration with its seed and the
K-1 after it, seed S into `DIR/seed-S` (a task planner's checkpoint, or a folder of motion
networks: `DIR/seed-S/place-gnn`), and writes `DIR/trainings.json`: the seeds, and the one a
shipped checkpoint is (the configuration's own seed). `eval world --checkpoint DIR` or
`--motion-checkpoints DIR` runs every training and reports over them.
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable
from pathlib import Path

from hsgplan.domain.errors import InvalidInputError
from hsgplan.files import write_atomically

RECORD = "trainings.json"
_SEED_FOLDER = re.compile(r"^seed-(\d+)$")


def seed_folder(root: Path, seed: int) -> Path:
    return Path(root) / f"seed-{seed}"


def training_seeds(first: int, count: int) -> list[int]:
    if count < 1:
        raise InvalidInputError(f"--seeds {count}: train at least once")
    return list(range(first, first + count))


def seed_folders(folder: Path | str | None) -> dict[int, Path] | None:
    """The trainings of a trainings folder by seed; None for any other folder."""
    if folder is None or not (Path(folder) / RECORD).is_file():
        return None
    found = {
        int(m.group(1)): p
        for p in sorted(Path(folder).iterdir())
        if p.is_dir() and (m := _SEED_FOLDER.match(p.name))
    }
    return dict(sorted(found.items())) or None


def record(root: Path, seeds: list[int], what: str) -> None:
    """Add `seeds` of `what` (a network's folder name, or "task") to the folder's record."""
    path = Path(root) / RECORD
    known = json.loads(path.read_text()) if path.is_file() else {}
    trained = known.setdefault("trained", {})
    trained[what] = sorted(set(trained.get(what, [])) | set(seeds))
    known["shipped_seed"] = known.get("shipped_seed", seeds[0])
    write_atomically(path, json.dumps(known, indent=2) + "\n")


def train_each(
    train: Callable[..., None], jobs: list[tuple[object, Path]], workers: int = 1
) -> None:
    """`train(config, folder)` for every job, `workers` at a time in processes of their own
    (one core each: a training is seeded, so where it runs changes nothing); in this process,
    with its progress shown, where one worker is asked for."""
    if workers <= 1 or len(jobs) <= 1:
        for config, folder in jobs:
            train(config, folder)
        return
    import multiprocessing
    import os
    from concurrent.futures import ProcessPoolExecutor

    from hsgplan.runner.engines import worker_start

    context = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(
        workers, mp_context=context, initializer=worker_start, initargs=(os.getpid(),)
    ) as pool:
        for done in [pool.submit(train, config, folder, False) for config, folder in jobs]:
            done.result()  # a failed training raises here, as it would alone


def paired(task: Path | str | None, motion: Path | str | None) -> dict[int | None, tuple]:
    """The (task, motion) folders of each training: by seed where either is a trainings folder
    (a plain folder serves every seed), else {None: (task, motion)}. Trainings folders of
    different seeds are refused in one line."""
    tasks, motions = seed_folders(task), seed_folders(motion)
    if tasks is None and motions is None:
        return {None: (task, motion)}
    if tasks is not None and motions is not None and set(tasks) != set(motions):
        raise InvalidInputError(
            f"'{task}' holds trainings of seeds {sorted(tasks)} and '{motion}' of "
            f"{sorted(motions)}: pair trainings of the same seeds"
        )
    seeds = sorted(tasks or motions or {})
    return {
        s: (
            str(tasks[s]) if tasks else task,
            str(motions[s]) if motions else motion,
        )
        for s in seeds
    }
