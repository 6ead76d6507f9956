"""The format of f_p's training images: synthetic samples (`perception.synthetic`) in chunks,
as `hsgplan collect images` (`collect/images.py`) writes them.

Format (version `FORMAT`), one compressed `.npz` per chunk of `CHUNK` samples in
`RUN/chunks/chunk-NNNNN.npz`, objects padded to `MAX_OBJECTS` (n samples, V views, K = 9
keypoints, M = `MAX_OBJECTS`):

| array     | dtype   | shape              | meaning                                              |
|-----------|---------|--------------------|------------------------------------------------------|
| index     | int32   | [n]                | the sample's index in the `(seed)` stream            |
| images    | uint8   | [n, V, H, W, 3]    | RGB                                                  |
| types     | int8    | [n, M]             | index into the collection's types, -1 past the last |
| instance  | int8    | [n, M]             | 1 for `cherries`, 2 for `cherries_2`, ...; 0 padding |
| poses     | float32 | [n, M, 7]          | position (m), quaternion xyzw; NaN padding           |
| keypoints | float32 | [n, V, M, K, 2]    | pixel (u right, v down; OpenCV's centres); NaN pad   |
| visible   | int32   | [n, V, M]          | the object's pixels in sight in that view            |
| cameras   | float32 | [n, V, 7]          | eye xyz, target xyz, vertical field of view (deg)    |
| sizes     | float32 | [n, M, 3]          | the object's size in its scene (m); NaN padding      |

`types` index the object types of the world the collection was staged in, in its scene file's
order (`collection_vocabulary`: the kitchen's, unless `collect images --scene` named another).
`sizes` is written by collections staged in a scene file's world; a chunk without it holds its
types' own sizes (`load_chunks` fills them in).

The run folder's `episodes.jsonl` logs every finished chunk with its file's SHA-256; a run
started again runs only the chunks not logged, and `load_chunks` refuses a file that is not
the one logged.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np

from hsgplan.data.world_trials import collection_worlds
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.world import World
from hsgplan.files import atomic, write_atomically
from hsgplan.perception.keypoints import KEYPOINTS
from hsgplan.perception.synthetic import (
    MAX_OBJECTS,
    P_ELSEWHERE,
    ImageSample,
    render_sample,
)
from hsgplan.perception.vocabulary import VIEW_COUNT, Vocabulary, training_world
from hsgplan.runner.run_folder import logged_rows

FORMAT = 1
CHUNK = 16


def chunk_path(run_dir: Path, chunk: int) -> Path:
    return run_dir / "chunks" / f"chunk-{chunk:05d}.npz"


def render_chunk(
    run_dir: str,
    seed: int,
    chunk: int,
    size: int,
    count: int,
    world: World,
    p_elsewhere: float = P_ELSEWHERE,
    views: int = VIEW_COUNT,
) -> dict:
    """Render a chunk's samples (of the first `count`, staged in scenes of `world`) into its
    file, written whole or not at all; the worker's entry point. Returns what the run log keeps
    of it."""
    indices = range(chunk * size, min((chunk + 1) * size, count))
    samples = [render_sample(seed, i, world, p_elsewhere, views) for i in indices]
    kept = [s for s in samples if s is not None]
    path = chunk_path(Path(run_dir), chunk)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic(path) as tmp:
        sized = world != training_world()  # the training world's chunks stay as they were
        np.savez_compressed(tmp, **pack(kept, world, views, sized))
        digest = hashlib.sha256(tmp.read_bytes()).hexdigest()
    unstaged = len(indices) - len(kept)
    return {"chunk": chunk, "samples": len(kept), "unstaged": unstaged, "sha256": digest}


def pack(
    samples: list[ImageSample],
    world: World,
    views: int = VIEW_COUNT,
    sized: bool = False,
) -> dict[str, np.ndarray]:
    """The arrays of a chunk of samples staged in `world` (`views` each; a chunk whose draws
    were all unstaged holds none); `sized`: the objects' sizes in it too."""
    n, v = len(samples), views
    h, w = world.cameras[0].height, world.cameras[0].width
    types = Vocabulary(world).types
    out = {
        "index": np.array([s.index for s in samples], dtype=np.int32),
        "images": np.zeros((n, v, h, w, 3), dtype=np.uint8),
        "types": np.full((n, MAX_OBJECTS), -1, dtype=np.int8),
        "instance": np.zeros((n, MAX_OBJECTS), dtype=np.int8),
        "poses": np.full((n, MAX_OBJECTS, 7), np.nan, dtype=np.float32),
        "keypoints": np.full((n, v, MAX_OBJECTS, KEYPOINTS, 2), np.nan, dtype=np.float32),
        "visible": np.zeros((n, v, MAX_OBJECTS), dtype=np.int32),
        "cameras": np.zeros((n, v, 7), dtype=np.float32),
    }
    for i, s in enumerate(samples):
        m = len(s.objects)
        out["images"][i] = s.images
        for j, name in enumerate(s.objects):
            type_name, k = world.split_instance(name)
            out["types"][i, j], out["instance"][i, j] = types.index(type_name), k
        out["poses"][i, :m] = s.poses
        out["keypoints"][i, :, :m] = s.keypoints
        out["visible"][i, :, :m] = s.visible
        out["cameras"][i] = [[*c.eye, *c.target, c.fov] for c in s.cameras]
    if sized:
        out["sizes"] = np.full((n, MAX_OBJECTS, 3), np.nan, dtype=np.float32)
        for i, s in enumerate(samples):
            out["sizes"][i, : len(s.objects)] = [world.object_type(o).size for o in s.objects]
    return out


def collection_vocabulary(run_dir: Path) -> Vocabulary:
    """The types and cameras of the world a collection was staged in (its configuration's
    scene file, else the kitchen): what its `types` index."""
    return Vocabulary(collection_worlds(run_dir, training_world())[0])


def load_chunks(run_dir: Path) -> dict[str, np.ndarray]:
    """Every logged chunk of a collection, concatenated in chunk order, every object's size
    in its scene given; a chunk file missing, damaged or not the one logged is refused in one
    line."""
    vocabulary = collection_vocabulary(run_dir)
    rows = sorted(
        (r["result"] for r in logged_rows(run_dir) if isinstance(r, dict) and "result" in r),
        key=lambda r: r["chunk"],
    )
    if not rows:
        raise InvalidInputError(f"'{run_dir}' holds no image chunks")
    parts = []
    for row in rows:
        path = chunk_path(run_dir, row["chunk"])
        if not path.is_file() or hashlib.sha256(path.read_bytes()).hexdigest() != row["sha256"]:
            raise InvalidInputError(f"'{path}' is missing or not the chunk logged; collect again")
        with np.load(path, allow_pickle=False) as data:
            part = {k: data[k] for k in data.files}
        if problem := chunk_problem(part, row["samples"], vocabulary):
            raise InvalidInputError(f"'{path}' is damaged: {problem}; collect again")
        if "sizes" not in part:  # its types' own sizes
            part["sizes"] = own_sizes(part["types"], vocabulary)
        parts.append(part)
    views = {p["images"].shape[1] for p in parts if len(p["images"])}
    if len(views) > 1:  # collections of several view counts train together (`train.joined`)
        raise InvalidInputError(f"'{run_dir}' mixes chunks of {sorted(views)} views")
    return {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}


def own_sizes(types: np.ndarray, vocabulary: Vocabulary) -> np.ndarray:
    """Each object's size as its type has it (NaN where there is none): [..., 3] for
    `types` [...] indices into the vocabulary's types (-1: none)."""
    table = np.array([vocabulary.object_type(k).size for k in range(len(vocabulary.types))])
    sizes = np.full((*types.shape, 3), np.nan, dtype=np.float32)
    sizes[types >= 0] = table[types[types >= 0]]
    return sizes


def chunk_problem(
    arrays: dict[str, np.ndarray], samples: int, vocabulary: Vocabulary
) -> str | None:
    """What breaks the format in a chunk's arrays (`pack`'s), or None: every array present,
    one row per sample as logged, the views and objects alike in every array, every type an
    index into the vocabulary's types (or -1, no object)."""
    names = ("index", "images", "types", "instance", "poses", "keypoints", "visible", "cameras")
    if missing := [n for n in names if n not in arrays]:
        return f"no {', '.join(missing)}"
    if any(len(arrays[n]) != samples for n in names):
        return f"not {samples} samples in every array"
    v = arrays["images"].shape[1] if arrays["images"].ndim == 5 else -1
    shapes = {
        "images": (v, vocabulary.views[0].height, vocabulary.views[0].width, 3),
        "types": (MAX_OBJECTS,),
        "instance": (MAX_OBJECTS,),
        "poses": (MAX_OBJECTS, 7),
        "keypoints": (v, MAX_OBJECTS, KEYPOINTS, 2),
        "visible": (v, MAX_OBJECTS),
        "cameras": (v, 7),
    }
    for name, shape in shapes.items():
        if arrays[name].shape[1:] != shape:
            return f"{name} of shape {arrays[name].shape[1:]}, not {shape}"
    if "sizes" in arrays and arrays["sizes"].shape[1:] != (MAX_OBJECTS, 3):
        return f"sizes of shape {arrays['sizes'].shape[1:]}, not {(MAX_OBJECTS, 3)}"
    types = arrays["types"]
    count = len(vocabulary.types)
    if types.dtype.kind not in "iu" or ((types < -1) | (types >= count)).any():
        return f"an object type outside -1 to {count - 1}"
    return None


def write_format(run_dir: Path, vocabulary: Vocabulary) -> None:
    """The format above, beside the chunks, for whoever reads them without this package."""
    doc = (__doc__ or "").split("Format", 1)[1].split("The run folder", 1)[0]
    types = list(vocabulary.types)
    text = json.dumps({"format": FORMAT, "types": types, "description": "Format" + doc}, indent=1)
    write_atomically(run_dir / "format.json", text + "\n")
