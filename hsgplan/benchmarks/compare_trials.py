"""How two collections of the same stream differ, trial by trial, after a change to the
primitives: `hsgplan bench compare-trials`, the basis of the place refusals' numbers in
docs/decisions.md.

Trials are matched by (task, attempt); those whose bins differ were not the same trial and are
counted apart, the rest by how their outcome changed.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import asdict, dataclass
from pathlib import Path

from hsgplan.data.motion_store import STATUSES, MotionData, chunk_files, dataset_world, load
from hsgplan.domain.checks import read_json
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.parameters import MotionPrimitive
from hsgplan.domain.scene import World
from hsgplan.domain.scene_file import recorded_worlds
from hsgplan.runner.run_folder import CONFIG
from hsgplan.scene_graph.names import names_world

# (task, attempt) -> (bins, status index)
Trials = dict[tuple[int, int], tuple[tuple[int, int], int]]


@dataclass(frozen=True)
class TrialComparison:
    shared: int
    same_outcome: int
    other_bins: int
    changed: dict[str, int]  # "old status -> new status": trials, most first

    def to_json(self) -> dict:
        return asdict(self)


def read_trials(path: Path) -> tuple[MotionPrimitive, Trials]:
    """The trials of a `*_trials.npz` file, or of a collector's work folder of chunk files."""
    if path.is_dir():
        files = list(chunk_files(path).values())
        if not files:
            raise InvalidInputError(f"'{path}': a folder without chunk files")
    else:
        files = [path]  # a missing or damaged file is refused by `load`, in one line
    world = _world(path)
    parts = [load(f, world) for f in files]
    if len({p.primitive for p in parts}) > 1:
        raise InvalidInputError(f"'{path}': chunks of both primitives")
    return parts[0].primitive, {k: v for p in parts for k, v in _rows(p)}


def _world(path: Path) -> World:
    """The world a collection was made in: a work folder's configuration, a file's manifest
    (the kitchen where they name no scene)."""
    if not path.is_dir():
        return dataset_world(path)
    config = path / CONFIG
    scene = read_json(config, "collection settings").get("scene") if config.exists() else None
    return recorded_worlds(scene, names_world(), path)[0]


def _rows(data: MotionData):
    for t, a, b, s in zip(data.task, data.attempt, data.bins, data.status, strict=True):
        yield (int(t), int(a)), ((int(b[0]), int(b[1])), int(s))


def compare(old: Trials, new: Trials) -> TrialComparison:
    shared = old.keys() & new.keys()
    changed: Counter[str] = Counter()
    other_bins = 0
    for key in shared:
        (old_bins, old_status), (new_bins, new_status) = old[key], new[key]
        if old_bins != new_bins:
            other_bins += 1
        elif old_status != new_status:
            changed[f"{STATUSES[old_status].value} -> {STATUSES[new_status].value}"] += 1
    same = len(shared) - other_bins - sum(changed.values())
    return TrialComparison(len(shared), same, other_bins, dict(changed.most_common()))


def compare_trials(old: Path, new: Path) -> TrialComparison:
    (old_kind, old_trials), (new_kind, new_trials) = read_trials(old), read_trials(new)
    if old_kind is not new_kind:
        raise InvalidInputError(f"'{old}' holds {old_kind.value} trials, '{new}' {new_kind.value}")
    return compare(old_trials, new_trials)
