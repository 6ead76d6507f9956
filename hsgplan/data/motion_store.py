"""The on-disk format of motion data: fixed-width numpy arrays, one row per trial.

Schema (version `SCHEMA_VERSION`), written beside the data as `schema.json`:

| array    | dtype   | shape     | meaning                                                       |
|----------|---------|-----------|---------------------------------------------------------------|
| task     | int32   | [S]       | task index in the `(primitive, seed)` stream                  |
| attempt  | int8    | [S]       | try within the task                                           |
| status   | int8    | [S]       | index into `STATUSES` (0 = success)                           |
| crowding | int8    | [S]       | objects already on the target surface / inside the shelf      |
| obj      | int8    | [S]       | index into `OBJECT_TYPES` of the object placed or pushed      |
| target   | int8    | [S]       | index into `ENTITY_TYPES` of the target surface or shelf      |
| bins     | int8    | [S, 2]    | (x_bin, y_bin) for place, (angle_bin, dist_bin) for push      |
| poses    | float32 | [S, 6, 7] | per object type: position, quaternion xyzw; NaN if absent     |

Simulated scenes hold at most one instance of each type, so a type index names an object. For
place the object placed is the one held. A dataset file (`place.npz`, `push.npz`) holds the
successful trials only; `place_trials.npz` / `push_trials.npz` every trial up to the last of
them, failures included; the collector's chunk files hold every trial plus `unstaged`.
About 190 bytes a row before compression.
"""

from __future__ import annotations

import json
import os
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hsgplan.data.motion_trials import ChunkResult, Trial
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.objects import ENTITY_TYPES
from hsgplan.domain.parameters import MotionPrimitive
from hsgplan.domain.world import OBJECT_TYPES
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.outcome import Status

SCHEMA_VERSION = 1
STATUSES: tuple[Status, ...] = tuple(Status)
TYPES: tuple[str, ...] = tuple(OBJECT_TYPES)
FIELDS = ("task", "attempt", "status", "crowding", "obj", "target", "bins", "poses")


@dataclass(frozen=True)
class MotionData:
    """Rows of trials (see the module's schema) for one primitive."""

    primitive: MotionPrimitive
    task: np.ndarray
    attempt: np.ndarray
    status: np.ndarray
    crowding: np.ndarray
    obj: np.ndarray
    target: np.ndarray
    bins: np.ndarray
    poses: np.ndarray

    def __len__(self) -> int:
        return len(self.task)

    @property
    def ok(self) -> np.ndarray:
        return self.status == STATUSES.index(Status.SUCCESS)

    def take(self, rows) -> MotionData:
        return MotionData(self.primitive, *(getattr(self, f)[rows] for f in FIELDS))

    def object_name(self, i: int) -> str:
        return TYPES[int(self.obj[i])]

    def target_name(self, i: int) -> str:
        return ENTITY_TYPES[int(self.target[i])]

    def scene_graph(self, i: int) -> GeometricSceneGraph:
        """s_g of row i, as the primitive found it."""
        poses = {
            TYPES[k]: Pose(tuple(map(float, p[:3])), tuple(map(float, p[3:])))
            for k, p in enumerate(self.poses[i])
            if not np.isnan(p[0])
        }
        held = self.object_name(i) if self.primitive is MotionPrimitive.PLACE else None
        return GeometricSceneGraph.from_poses(poses, held=held)


def from_trials(primitive: MotionPrimitive, trials: list[Trial]) -> MotionData:
    s = len(trials)
    poses = np.full((s, len(TYPES), 7), np.nan, dtype=np.float32)
    for i, t in enumerate(trials):
        for node in t.before.nodes:
            poses[i, TYPES.index(node.type_name)] = node.pose.position + node.pose.orientation
    return MotionData(
        primitive,
        np.array([t.task for t in trials], dtype=np.int32),
        np.array([t.attempt for t in trials], dtype=np.int8),
        np.array([STATUSES.index(t.status) for t in trials], dtype=np.int8),
        np.array([t.crowding for t in trials], dtype=np.int8),
        np.array([TYPES.index(t.obj) for t in trials], dtype=np.int8),
        np.array([ENTITY_TYPES.index(t.target) for t in trials], dtype=np.int8),
        np.array([t.bins for t in trials], dtype=np.int8).reshape(s, 2),
        poses,
    )


def save(path: Path, data: MotionData, **extra: int) -> None:
    """Write atomically (a temporary file renamed), so an interruption leaves no half file."""
    tmp = path.with_name(path.name + ".tmp.npz")
    arrays = {f: getattr(data, f) for f in FIELDS}
    np.savez_compressed(tmp, primitive=np.array(data.primitive.value), **arrays, **extra)
    os.replace(tmp, path)


def load(path: Path) -> MotionData:
    """Read a dataset or chunk file; a missing or damaged file is refused in one line."""
    if not path.exists():
        raise InvalidInputError(f"'{path}': no such motion data file")
    try:
        with np.load(path, allow_pickle=False) as z:
            return MotionData(MotionPrimitive(str(z["primitive"])), *(z[f] for f in FIELDS))
    except (OSError, ValueError, KeyError, zipfile.BadZipFile) as e:
        raise InvalidInputError(f"'{path}' is not a readable motion data file ({e})") from None


def unstaged_of(path: Path) -> int:
    with np.load(path, allow_pickle=False) as z:
        return int(z["unstaged"])


def chunk_path(folder: Path, chunk: int) -> Path:
    return folder / f"chunk-{chunk:06d}.npz"


def save_chunk(folder: Path, result: ChunkResult) -> None:
    data = from_trials(result.primitive, list(result.trials))
    save(chunk_path(folder, result.chunk), data, unstaged=np.array(result.unstaged))


def concat(primitive: MotionPrimitive, parts: list[MotionData]) -> MotionData:
    if not parts:
        return from_trials(primitive, [])
    return MotionData(primitive, *(np.concatenate([getattr(p, f) for p in parts]) for f in FIELDS))


def write_schema(folder: Path) -> None:
    doc = (__doc__ or "").split("Schema", 1)[1]
    schema = {
        "version": SCHEMA_VERSION,
        "statuses": [s.value for s in STATUSES],
        "object_types": list(TYPES),
        "entity_types": list(ENTITY_TYPES),
        "fields": FIELDS,
        "description": "Schema" + doc,
    }
    (folder / "schema.json").write_text(json.dumps(schema, indent=1) + "\n")
