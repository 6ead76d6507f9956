"""The on-disk format of motion data: fixed-width numpy arrays, one row per trial.

Schema (version `SCHEMA_VERSION`), written beside the data as `schema.json`:

| array    | dtype   | shape     | meaning                                                       |
|----------|---------|-----------|---------------------------------------------------------------|
| task     | int32   | [S]       | task index in the `(primitive, seed)` stream                  |
| attempt  | int8    | [S]       | try within the task                                           |
| status   | int8    | [S]       | index into `STATUSES` (0 = success)                           |
| crowding | int8    | [S]       | objects already on the target surface / inside the shelf      |
| obj      | int8    | [S]       | index into the world's object types, of the object moved      |
| target   | int8    | [S]       | index into the world's entity types, of the target            |
| bins     | int8    | [S, 2]    | (x_bin, y_bin) for place, (angle_bin, dist_bin) for push      |
| poses    | float32 | [S, T, 7] | per object type: position, quaternion xyzw; NaN if absent     |

The world is the kitchen (T = 6), or the scene file a collection was made in, which the
dataset's manifest names (`scene`) and `schema.json` lists the types of. Collected round a
folder of scene files (all of the same types), chunk k of the tasks (`task // tasks_per_chunk`,
which the manifest records) was staged in the folder's k-th file, counted round. Simulated
scenes hold at most one instance of each type, so a type index names an object. For place the
object placed is the one held. A dataset file (`place.npz`, `push.npz`) holds the
successful trials only; `place_trials.npz` / `push_trials.npz` every trial up to the last of
them, failures included; the collector's chunk files hold every trial plus `unstaged`.
About 190 bytes a row before compression.
"""

from __future__ import annotations

import hashlib
import json
import re
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from hsgplan.data.motion_trials import ChunkResult, Trial
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.parameters import BINS, MotionPrimitive
from hsgplan.domain.scene import World
from hsgplan.domain.scene_file import recorded_worlds, scene_file_names
from hsgplan.files import atomic, write_atomically
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.geometry import Pose
from hsgplan.scene_graph.names import TYPE_NAMES, names_world
from hsgplan.sim.outcome import Status

# 2: a place that leaves an object unpickable is labelled `blocks_pick`; 3: a push task may
# start where a short push left the can (`MotionTask.front_gap`), place rows as in 2.
SCHEMA_VERSION = 3
CHUNK_FORMAT = 2  # 2: a chunk carries its index and seed, checked on load
STATUSES: tuple[Status, ...] = tuple(Status)
TYPES: tuple[str, ...] = TYPE_NAMES
SCHEMA = "schema.json"
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
    world: World  # whose object and entity types the indices name
    # Collected round a folder of scene files: the world of each chunk of tasks, in turn (none:
    # every row is of `world`); see the module's schema.
    worlds: tuple[World, ...] = ()
    tasks_per_chunk: int = 0

    @property
    def types(self) -> tuple[str, ...]:
        return tuple(self.world.object_types)

    @property
    def entities(self) -> tuple[str, ...]:
        return tuple(self.world.entity_types)

    def __len__(self) -> int:
        return len(self.task)

    @property
    def ok(self) -> np.ndarray:
        return self.status == STATUSES.index(Status.SUCCESS)

    def take(self, rows) -> MotionData:
        return replace(self, **{f: getattr(self, f)[rows] for f in FIELDS})

    def world_of(self, i: int) -> World:
        """The world row i was staged in."""
        if not self.worlds:
            return self.world
        return self.worlds[(int(self.task[i]) // self.tasks_per_chunk) % len(self.worlds)]

    def object_name(self, i: int) -> str:
        return self.types[int(self.obj[i])]

    def target_name(self, i: int) -> str:
        return self.entities[int(self.target[i])]

    def scene_graph(self, i: int) -> GeometricSceneGraph:
        """s_g of row i, as the primitive found it."""
        types = self.types
        poses = {
            types[k]: Pose(tuple(map(float, p[:3])), tuple(map(float, p[3:])))
            for k, p in enumerate(self.poses[i])
            if not np.isnan(p[0])
        }
        held = self.object_name(i) if self.primitive is MotionPrimitive.PLACE else None
        return GeometricSceneGraph.from_poses(poses, held=held, world=self.world_of(i))


def from_trials(primitive: MotionPrimitive, trials: list[Trial], world: World) -> MotionData:
    s = len(trials)
    types, entities = tuple(world.object_types), tuple(world.entity_types)
    poses = np.full((s, len(types), 7), np.nan, dtype=np.float32)
    for i, t in enumerate(trials):
        for node in t.before.nodes:
            poses[i, types.index(node.type_name)] = node.pose.position + node.pose.orientation
    return MotionData(
        primitive,
        np.array([t.task for t in trials], dtype=np.int32),
        np.array([t.attempt for t in trials], dtype=np.int8),
        np.array([STATUSES.index(t.status) for t in trials], dtype=np.int8),
        np.array([t.crowding for t in trials], dtype=np.int8),
        np.array([types.index(t.obj) for t in trials], dtype=np.int8),
        np.array([entities.index(t.target) for t in trials], dtype=np.int8),
        np.array([t.bins for t in trials], dtype=np.int8).reshape(s, 2),
        poses,
        world,
    )


def save(path: Path, data: MotionData, **extra: np.ndarray) -> None:
    """Write atomically (a temporary file renamed), so an interruption leaves no half file;
    the temporary name never looks like a chunk or a dataset."""
    arrays = {f: getattr(data, f) for f in FIELDS}
    with atomic(path) as tmp, open(tmp, "wb") as f:
        np.savez_compressed(f, primitive=np.array(data.primitive.value), **arrays, **extra)


def load(path: Path, world: World) -> MotionData:
    """Read a dataset or chunk file of `world`; a missing or damaged file is refused in one
    line."""
    return _read(path, world)[0]


def _read(path: Path, world: World) -> tuple[MotionData, dict[str, int]]:
    """The rows and the integer extras (a chunk's index, seed, unstaged count) of a file."""
    if not path.is_file():
        raise InvalidInputError(f"'{path}': no such motion data file")
    try:
        with np.load(path, allow_pickle=False) as z:
            kind = MotionPrimitive(str(z["primitive"]))
            data = MotionData(kind, *(z[f] for f in FIELDS), world=world)
            extras = {k: int(z[k]) for k in z.files if k not in FIELDS and k != "primitive"}
    except Exception as e:  # zip, numpy and value errors alike: a damaged file, one line
        raise InvalidInputError(f"'{path}' is not a readable motion data file ({e})") from None
    n = len(data.task)
    shapes = [getattr(data, f).shape[:1] == (n,) for f in FIELDS]
    poses_shape = (len(data.types), 7)
    if not all(shapes) or data.bins.shape[1:] != (2,) or data.poses.shape[1:] != poses_shape:
        raise InvalidInputError(f"'{path}' does not follow the motion data schema")
    if problem := row_problem(data):
        raise InvalidInputError(f"'{path}' is damaged: {problem}")
    return data, extras


def row_problem(data: MotionData) -> str | None:
    """What breaks the schema in `data`'s rows (the first row and field), or None: every index
    in range, every pose finite or absent, the object acted on and an object target present.
    A damaged or hand-edited file is refused here rather than deep inside training."""
    indices = ("task", "attempt", "status", "crowding", "obj", "target", "bins")
    if any(getattr(data, f).dtype.kind not in "iu" for f in indices):
        return "an index array does not hold integers"
    if data.poses.dtype.kind != "f":
        return "poses are not floating point"
    nx, ny = BINS[data.primitive]
    limits = {
        "task": (data.task, None),
        "attempt": (data.attempt, None),
        "crowding": (data.crowding, None),
        "status": (data.status, len(STATUSES)),
        "obj": (data.obj, len(data.types)),
        "target": (data.target, len(data.entities)),
        "x or angle bin": (data.bins[:, 0], nx),
        "y or distance bin": (data.bins[:, 1], ny),
    }
    for name, (values, end) in limits.items():
        bad = (values < 0) | (values >= end if end is not None else False)
        if bad.any():
            i = int(np.argmax(bad))
            bound = f"0 to {end - 1}" if end is not None else "at least 0"
            return f"row {i}: {name} {int(values[i])} (must be {bound})"
    absent = np.isnan(data.poses).all(axis=2)
    if not (absent | np.isfinite(data.poses).all(axis=2)).all():
        return "a pose is partly missing or not finite"
    rows = np.arange(len(data))
    if len(data) and absent[rows, data.obj.astype(np.int64)].any():
        i = int(np.argmax(absent[rows, data.obj.astype(np.int64)]))
        return f"row {i}: the object acted on, {data.object_name(i)}, has no pose"
    target_is_object = data.target < len(data.types)
    target = np.where(target_is_object, data.target, 0).astype(np.int64)
    bad = target_is_object & (absent[rows, target] | (data.target == data.obj))
    if bad.any():
        i = int(np.argmax(bad))
        return f"row {i}: target {data.target_name(i)} is absent or the object itself"
    return None


CHUNK_NAME = re.compile(r"chunk-(\d{6})\.npz")


def chunk_path(folder: Path, chunk: int) -> Path:
    return folder / f"chunk-{chunk:06d}.npz"


def chunk_files(folder: Path) -> dict[int, Path]:
    """The chunk files of a work folder by index (nothing else that lies there)."""
    found = {}
    for path in folder.iterdir():
        if m := CHUNK_NAME.fullmatch(path.name):
            found[int(m.group(1))] = path
    return dict(sorted(found.items()))


def save_chunk(folder: Path, result: ChunkResult, world: World) -> None:
    data = from_trials(result.primitive, list(result.trials), world)
    extras = {"unstaged": result.unstaged, "chunk": result.chunk, "seed": result.seed}
    save(chunk_path(folder, result.chunk), data, **{k: np.array(v) for k, v in extras.items()})


def load_chunk(
    path: Path,
    primitive: MotionPrimitive,
    seed: int,
    chunk: int,
    tasks_per_chunk: int,
    world: World,
) -> tuple[MotionData, int]:
    """A chunk's rows and unstaged count, checked to be the chunk its name says of this
    collection: a damaged chunk, or one copied from another place, is refused in one line."""
    data, extras = _read(path, world)
    tasks = range(chunk * tasks_per_chunk, (chunk + 1) * tasks_per_chunk)
    own = (
        data.primitive is primitive
        and extras.get("chunk") == chunk
        and extras.get("seed") == seed
        and all(int(t) in tasks for t in np.unique(data.task))
    )
    if not own or "unstaged" not in extras:
        raise InvalidInputError(f"'{path}' is not chunk {chunk} of this collection")
    return data, extras["unstaged"]


def concat(primitive: MotionPrimitive, parts: list[MotionData], world: World) -> MotionData:
    if not parts:
        return from_trials(primitive, [], world)
    joined = (np.concatenate([getattr(p, f) for p in parts]) for f in FIELDS)
    return MotionData(primitive, *joined, world=world)


def write_schema(folder: Path, world: World) -> None:
    doc = (__doc__ or "").split("Schema", 1)[1]
    schema = {
        "version": SCHEMA_VERSION,
        "statuses": [s.value for s in STATUSES],
        "object_types": list(world.object_types),
        "entity_types": list(world.entity_types),
        "fields": FIELDS,
        "description": "Schema" + doc,
    }
    write_atomically(folder / SCHEMA, json.dumps(schema, indent=1) + "\n")


def manifest_path(dataset: Path) -> Path:
    return dataset.with_suffix(".json")


def write_manifest(dataset: Path, settings: dict) -> None:
    """What made a dataset file, and its checksum, as `place.json` beside `place.npz`."""
    manifest = settings | {"sha256": hashlib.sha256(dataset.read_bytes()).hexdigest()}
    write_atomically(manifest_path(dataset), json.dumps(manifest, indent=1) + "\n")


def read_manifest(dataset: Path) -> dict | None:
    """A dataset file's manifest (None when there is none or it cannot be read)."""
    try:
        manifest = json.loads(manifest_path(dataset).read_bytes())
    except (OSError, ValueError):
        return None
    return manifest if isinstance(manifest, dict) else None


def load_dataset(path: Path, primitive: MotionPrimitive | None = None) -> MotionData:
    """A dataset file (of `primitive`, when given), checked against its manifest where it has
    one (checksum, primitive, number of successes): a file replaced, swapped or damaged since
    it was collected is refused in one line."""
    manifest = read_manifest(path)
    if (
        manifest
        and path.is_file()
        and (hashlib.sha256(path.read_bytes()).hexdigest() != manifest.get("sha256"))
    ):
        raise InvalidInputError(
            f"'{path}' does not match its manifest {manifest_path(path).name} "
            "(damaged or replaced); collect it again"
        )
    worlds = dataset_worlds(path, manifest)
    data = load(path, worlds[0])
    if manifest and "tasks_per_chunk" in manifest:  # collected round a folder of scene files
        data = replace(data, worlds=tuple(worlds), tasks_per_chunk=_round(path, manifest))
    if primitive is not None and data.primitive is not primitive:
        raise InvalidInputError(
            f"'{path}' holds {data.primitive.value} trials, not {primitive.value} ones"
        )
    if manifest and manifest.get("primitive", data.primitive.value) != data.primitive.value:
        raise InvalidInputError(
            f"'{path}' holds {data.primitive.value} trials; its manifest says "
            f"{manifest.get('primitive')!r}"
        )
    if manifest and manifest.get("samples", int(data.ok.sum())) != int(data.ok.sum()):
        raise InvalidInputError(
            f"'{path}' holds {int(data.ok.sum())} successes; its manifest says "
            f"{manifest.get('samples')!r}"
        )
    return data


def dataset_world(path: Path, manifest: dict | None = None) -> World:
    """The world whose types a dataset file's indices name (the first of its worlds)."""
    return dataset_worlds(path, manifest)[0]


def dataset_worlds(path: Path, manifest: dict | None = None) -> list[World]:
    """The worlds a dataset file was collected in: the scene file or folder its manifest
    names, else the kitchen (data collected before scenes could be given names none). A scene
    not found here, or a folder of scenes of other types, is refused in one line."""
    manifest = read_manifest(path) if manifest is None else manifest
    scene = (manifest or {}).get("scene")
    return one_set_of_types(recorded_worlds(scene, names_world(), path), scene)


def _round(path: Path, manifest: dict) -> int:
    """The chunking of a collection round a folder of scene files, refused in one line where
    the folder no longer holds the files it was collected round (rows would change world)."""
    per_chunk, names, scene = (manifest.get(k) for k in ("tasks_per_chunk", "scene_files", "scene"))
    if not isinstance(per_chunk, int) or per_chunk < 1 or not isinstance(scene, str):
        raise InvalidInputError(
            f"'{path}': its manifest's tasks_per_chunk {per_chunk!r} or scene {scene!r} is wrong"
        )
    if names != scene_file_names(scene):
        raise InvalidInputError(
            f"'{path}' was collected round other scene files than '{scene}' "
            "holds now; collect it again"
        )
    return per_chunk


def one_set_of_types(worlds: list[World], scene: object) -> list[World]:
    """`worlds`, refused in one line unless they name the same object and entity types (the
    columns of one motion dataset index one set of them)."""
    kinds = {(tuple(w.object_types), tuple(w.entity_types)) for w in worlds}
    if len(kinds) > 1:
        raise InvalidInputError(
            f"the scene files in '{scene}' name different objects or fixtures; a motion "
            "dataset is collected round scenes of the same types"
        )
    return worlds
