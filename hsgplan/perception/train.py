"""Training the keypoint network on a synthetic image collection: `hsgplan train perception`.

Every (sample, view) image is one example; its targets are the belief maps and affinity fields
(`perception.maps.targets`) of the objects in sight in it (at least `MIN_VISIBLE` pixels), their
keypoints named as that view names them (the pose's canonical look-alike for the camera), made
batch by batch. Every stage is supervised, as in DOPE, though not with its squared error
(`loss_of` says why). Labels come from the renderer: the
poses the scene was staged in, projected through the camera that rendered it. The checkpoint
is a folder (`train_config.json`, `config.json`, `model.safetensors`, `manifest.json`) and a
run started again with the same configuration continues from its last saved epoch.
"""

from __future__ import annotations

import math
import random
from collections.abc import Callable
from dataclasses import asdict, dataclass, replace
from pathlib import Path

import cv2
import numpy as np
import torch

from hsgplan import training
from hsgplan.checkpoint import fingerprint
from hsgplan.domain.checks import (
    BOUNDS,
    check_fields,
    from_settings,
    setting,
)
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.world import ObjectType
from hsgplan.perception.colour import (
    BACKGROUND,
    PATCH,
    ColourConfig,
    ColourNet,
    features,
    load_colour,
)
from hsgplan.perception.colour import FOLDER as COLOUR_FOLDER
from hsgplan.perception.images import chunk_path, collection_vocabulary, load_chunks
from hsgplan.perception.keypoints import KEYPOINTS, PinholeCamera, view_keypoints
from hsgplan.perception.maps import targets
from hsgplan.perception.model import STRIDE, PerceptionNetConfig, build, load_perception_net
from hsgplan.perception.vocabulary import (
    TYPES,
    Vocabulary,
    read_vocabulary,
    write_vocabulary,
)
from hsgplan.runner.run_folder import logged_rows
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.render import Camera

MIN_VISIBLE = 30  # pixels of an object in sight for its keypoints to be a target
BACKGROUND_PATCHES = 3  # patches of background an image, for the colour network (`colour`)


@dataclass(frozen=True)
class PerceptionTrainConfig:
    images: str = "runs/collect-images"
    seed: int = setting(0, **BOUNDS["seed"])
    epochs: int = setting(9, lo=1, hi=10_000)
    lr: float = setting(1e-3, above=0, hi=10)
    # The learning rate falls along a half cosine from `lr` to this fraction of it by the last
    # epoch (1: constant); set per epoch, so a resumed run is where it would have been.
    final_lr_fraction: float = setting(0.05, above=0, hi=1)
    batch_size: int = setting(16, lo=1, hi=4096)
    width: int = setting(24, lo=1, hi=512)
    stages: int = setting(2, lo=1, hi=6)
    stride: int = setting(4, lo=2, hi=4)  # see `perception.model`: 4, or 2 (not trained yet)
    save_every: int = setting(1, lo=1, hi=10_000)
    threads: int = setting(2, **BOUNDS["workers"])
    # A trained checkpoint folder whose weights start the network (a stride-2 network from a
    # stride-4 one of the same sizes, its refinement head fresh); "": from scratch.
    init: str = ""
    positive_weight: float = setting(20.0, lo=0, hi=10_000)  # see `loss_of`
    field_weight: float = setting(0.1, lo=0, hi=10_000)  # see `loss_of`

    def __post_init__(self) -> None:
        check_fields(self)

    def net_config(self, types: int = len(TYPES)) -> PerceptionNetConfig:
        """The network's sizes, for `types` type channels (its vocabulary's)."""
        return PerceptionNetConfig(
            types=types, width=self.width, stages=self.stages, stride=self.stride
        )

    @property
    def folders(self) -> list[Path]:
        """The image collections trained on: `images` names one, or several joined by commas."""
        return [Path(p.strip()) for p in self.images.split(",") if p.strip()]

    @staticmethod
    def from_json(d: dict) -> PerceptionTrainConfig:
        return from_settings(PerceptionTrainConfig, d)


@dataclass(frozen=True)
class Examples:
    """Every (sample, view) image with the keypoints and types of the objects in sight in it:
    images [E, 3, H, W] uint8; keypoints and types, E arrays of [M, 9, 2] and [M]; and the
    keypoints of every object in the scene, in sight or not (cuboids, E arrays of [N, 9, 2]:
    what is not background). Targets are made per batch: kept for a whole collection they
    would take some 1.4 MB an image."""

    images: torch.Tensor
    keypoints: list[np.ndarray]
    types: list[np.ndarray]
    cuboids: list[np.ndarray]

    def targets(
        self, take: list[int], types_count: int, stride: int = STRIDE
    ) -> tuple[torch.Tensor, torch.Tensor]:
        """Belief maps and affinity fields of the images `take`: [B, C, h, w], [B, F, h, w]."""
        h, w = self.images.shape[2] // stride, self.images.shape[3] // stride
        maps = [targets(self.keypoints[i], self.types[i], types_count, h, w, stride) for i in take]
        return (
            torch.from_numpy(np.stack([b for b, _ in maps])),
            torch.from_numpy(np.stack([f for _, f in maps])),
        )


def examples(data: dict[str, np.ndarray], vocabulary: Vocabulary) -> Examples:
    """Every (sample, view) of a loaded collection whose types index `vocabulary`'s, its
    keypoints named as that view names them (`perception.keypoints.view_keypoints`, from the
    stored poses, sizes and cameras)."""
    images, keypoints, types, cuboids = [], [], [], []
    n, views, height, width = data["images"].shape[:4]
    # no sizes: each type's own
    sizes = data.get("sizes", np.full((*data["types"].shape, 3), np.nan, dtype=np.float32))
    for i in range(n):
        for v in range(views):
            seen = (data["types"][i] >= 0) & (data["visible"][i, v] >= MIN_VISIBLE)
            eye, target, fov = (
                data["cameras"][i, v, :3],
                data["cameras"][i, v, 3:6],
                data["cameras"][i, v, 6],
            )
            camera = PinholeCamera.of(
                Camera(width, height, tuple(map(float, eye)), tuple(map(float, target)), float(fov))
            )
            present = data["types"][i] >= 0
            every = np.asarray(
                [
                    view_keypoints(_sized(vocabulary, t, size), _pose(p), camera)
                    for t, p, size in zip(
                        data["types"][i][present],
                        data["poses"][i][present],
                        sizes[i][present],
                        strict=True,
                    )
                ],
                dtype=np.float32,
            ).reshape(-1, KEYPOINTS, 2)
            images.append(torch.from_numpy(data["images"][i, v]).permute(2, 0, 1))
            keypoints.append(every[seen[present]])
            types.append(data["types"][i][seen].astype(np.int64))
            cuboids.append(every)
    return Examples(torch.stack(images), keypoints, types, cuboids)


def joined(parts: list[Examples]) -> Examples:
    """The examples of several collections, in order."""
    return Examples(
        torch.cat([p.images for p in parts]),
        [k for p in parts for k in p.keypoints],
        [t for p in parts for t in p.types],
        [c for p in parts for c in p.cuboids],
    )


def _sized(vocabulary: Vocabulary, t: int, size: np.ndarray) -> ObjectType:
    """The vocabulary's type `t` at the size it had in its scene (a layout resizes its
    groceries); NaN: the type's own."""
    own = vocabulary.object_type(t)
    return own if np.isnan(size).any() else replace(own, size=tuple(map(float, size)))


def _pose(p: np.ndarray) -> Pose:
    return Pose(tuple(map(float, p[:3])), tuple(map(float, p[3:])))


def loss_of(
    outputs,
    beliefs: torch.Tensor,
    fields: torch.Tensor,
    positive_weight: float = 0.0,
    field_weight: float = 1.0,
) -> torch.Tensor:
    """Every stage's maps against the targets, summed over stages.

    Beliefs: binary cross-entropy against the Gaussian targets, a cell's term weighing
    1 + `positive_weight` x its target. Its minimum is the target itself, so a peak keeps the
    shape that sub-cell refinement reads; unlike DOPE's squared error its gradient does not
    fade where the sigmoid saturates, and the weight stops the network settling on "nothing
    anywhere" (the maps are almost all zeros).
    Fields: smooth L1 in cells, only where a target is set (near a corner), the only cells
    decoding reads; `field_weight` x their mean.

    Shapes:
        outputs: stages of (beliefs [B, C, h, w] in 0..1, fields [B, F, h, w]);
        beliefs: [B, C, h, w]; fields: [B, F, h, w], F even (x, y pairs).
    """
    weight = 1.0 + positive_weight * beliefs
    pairs = fields.reshape(fields.shape[0], -1, 2, *fields.shape[2:])
    near = (pairs != 0).any(dim=2, keepdim=True).expand_as(pairs).reshape(fields.shape)
    count = near.sum().clamp(min=1)
    total = torch.zeros(())
    for b, f in outputs:
        p = b.clamp(1e-4, 1 - 1e-4)
        total = total + torch.nn.functional.binary_cross_entropy(p, beliefs, weight=weight)
        smooth = torch.nn.functional.smooth_l1_loss(f, fields, reduction="none")
        total = total + field_weight * (smooth * near).sum() / count
    return total


def epoch_lr(config: PerceptionTrainConfig, epoch: int) -> float:
    """The learning rate of epoch `epoch` (0-based)."""
    done = epoch / max(1, config.epochs - 1)
    low = config.final_lr_fraction
    return config.lr * (low + (1 - low) * 0.5 * (1 + math.cos(math.pi * done)))


def train_perception(
    config: PerceptionTrainConfig,
    out: Path,
    on_epoch: Callable[[int, float], None] | None = None,
    on_batch: Callable[[int, int], None] | None = None,
) -> None:
    """Train (or go on training) the keypoint network into the checkpoint folder `out`, then
    the colour network that names types (`perception.colour`) into `out/colour/` (seconds);
    `on_batch` sees (images done this epoch, images in an epoch) after every batch."""
    config.net_config()  # a stride the network does not have: refused before any write
    if not config.folders:
        raise InvalidInputError("no image collection named")
    vocabulary = _vocabulary(config)  # collections of other looks: refused before any write
    torch.manual_seed(config.seed)
    net_config = config.net_config(len(vocabulary.types))
    model = build(net_config)
    if config.init:  # one that does not fit: refused before any write
        _start_from(model, load_perception_net(Path(config.init))[0])
    parts = [load_chunks(f) for f in config.folders]  # missing or damaged: refused, too
    chunks = [chunk_path(f, r["result"]["chunk"]) for f in config.folders for r in logged_rows(f)]
    data_print = fingerprint(chunks + ([Path(config.init)] if config.init else []))
    training.claim(out, asdict(config), asdict(PerceptionTrainConfig()), data_print)
    write_vocabulary(out, vocabulary)
    # collections of different view counts join too
    found = joined([examples(p, vocabulary) for p in parts])
    if len(found.images) == 0:
        raise InvalidInputError(f"no images in '{config.images}'")
    if not training.finished(out):
        _train_keypoints(config, net_config, model, found, out, data_print, on_epoch, on_batch)
    count = len(vocabulary.types)
    colour = ColourConfig(types=count + 1, seed=config.seed)
    train_colour(colour_samples(found, background=count), out / COLOUR_FOLDER, colour)


def _vocabulary(config: PerceptionTrainConfig) -> Vocabulary:
    """The types and cameras the collections were staged with, which the networks learn
    (`perception.vocabulary`); collections (or an init checkpoint) of other looks, or of them
    in another order, are refused in one line."""
    first, *others = config.folders
    vocabulary = collection_vocabulary(first)
    for folder in others:
        if not collection_vocabulary(folder).same_looks(vocabulary):
            raise InvalidInputError(
                f"'{folder}' was staged among other groceries or cameras than '{first}'; "
                "collections train together only over the same ones"
            )
    if config.init and not read_vocabulary(config.init).same_looks(vocabulary):
        raise InvalidInputError(
            f"the init checkpoint '{config.init}' learned other groceries or cameras than "
            f"the images '{first}' show"
        )
    return vocabulary


def colour_samples(found: Examples, background: int = BACKGROUND) -> list[tuple[np.ndarray, int]]:
    """(colour features at the centroid, type) of every in-sight object of every image, and
    (those of `BACKGROUND_PATCHES` patches outside every object, the class `background`: the
    one after the types)."""
    out = []
    for e, (image, points, kinds, every) in enumerate(
        zip(found.images, found.keypoints, found.types, found.cuboids, strict=True)
    ):
        pixels = image.permute(1, 2, 0).numpy()
        for p, t in zip(points, kinds, strict=True):
            if (row := features(pixels, p[-1])) is not None:
                out.append((row, int(t)))
        out += [(row, background) for row in _background(pixels, every, np.random.default_rng(e))]
    return out


def _background(pixels: np.ndarray, cuboids: np.ndarray, rng: np.random.Generator) -> list:
    """The features of up to `BACKGROUND_PATCHES` random patches of an [H, W, 3] image lying
    wholly outside every object's projected cuboid (`cuboids`: [M, 9, 2] keypoints)."""
    inside = np.zeros(pixels.shape[:2], np.uint8)
    for corners in cuboids[:, :8]:
        if np.isfinite(corners).all():
            cv2.fillConvexPoly(inside, cv2.convexHull(np.round(corners).astype(np.int32)), 1)
    inside = cv2.dilate(inside, np.ones((2 * PATCH + 1, 2 * PATCH + 1), np.uint8))
    v, u = np.nonzero(inside == 0)
    if not len(u):
        return []
    take = rng.choice(len(u), size=min(BACKGROUND_PATCHES, len(u)), replace=False)
    return [features(pixels, np.array([u[k], v[k]])) for k in take]


def _start_from(model: torch.nn.Module, trained: torch.nn.Module) -> None:
    """Copy every weight of `trained` into `model`, whose other weights (a refinement head)
    keep their start; refused in one line unless each has its place, of its shape, there."""
    own, weights = model.state_dict(), trained.state_dict()
    if any(k not in own or own[k].shape != v.shape for k, v in weights.items()):
        raise InvalidInputError(
            "the init checkpoint's network differs from this one in more than its stride"
        )
    model.load_state_dict(weights, strict=False)


def _train_keypoints(
    config: PerceptionTrainConfig,
    net_config: PerceptionNetConfig,
    model: torch.nn.Module,
    found: Examples,
    out: Path,
    data_print: str,
    on_epoch: Callable[[int, float], None] | None,
    on_batch: Callable[[int, int], None] | None,
) -> None:
    torch.set_num_threads(config.threads)
    optim = torch.optim.Adam(model.parameters(), lr=config.lr)
    start = training.resume(out, model, optim, data_print)
    for epoch in range(start, config.epochs):
        for group in optim.param_groups:
            group["lr"] = epoch_lr(config, epoch)
        model.train()
        order = list(range(len(found.images)))
        random.Random(f"{config.seed}-{epoch}").shuffle(order)
        total = 0.0
        for i in range(0, len(order), config.batch_size):
            take = order[i : i + config.batch_size]
            image = found.images[torch.tensor(take)].float() / 255.0
            beliefs, fields = found.targets(take, net_config.types, net_config.stride)
            loss = loss_of(
                model(image), beliefs, fields, config.positive_weight, config.field_weight
            )
            optim.zero_grad()
            loss.backward()
            optim.step()
            total += loss.detach().item() * len(take)
            if on_batch:
                on_batch(i + len(take), len(order))
        training.check_loss(total, "the keypoint network", epoch + 1)
        if on_epoch:
            on_epoch(epoch + 1, total / len(order))
        if (epoch + 1) % config.save_every == 0 and epoch + 1 < config.epochs:
            training.save_progress(out, model, optim, epoch + 1, data_print)
    training.finish(out, model.eval(), net_config.to_json())


def train_colour(
    samples: list[tuple[np.ndarray, int]], out: Path, config: ColourConfig | None = None
) -> ColourNet:
    """Fit the colour network to (features, type index) pairs into the folder `out` (a
    finished one is loaded, not redone)."""
    config = config or ColourConfig()
    training.claim(out, config.to_json())
    if training.finished(out):
        return load_colour(out)
    torch.manual_seed(config.seed)
    order = list(range(len(samples)))
    random.Random(config.seed).shuffle(order)
    x = torch.from_numpy(np.stack([samples[i][0] for i in order]))
    y = torch.tensor([samples[i][1] for i in order])
    model = ColourNet(config)
    optim = torch.optim.Adam(model.parameters(), lr=config.lr)
    for _ in range(config.steps):  # full batch: a few thousand rows of four numbers
        loss = torch.nn.functional.cross_entropy(model(x), y)
        optim.zero_grad()
        loss.backward()
        optim.step()
    training.check_loss(float(loss.detach()), "the colour network", config.steps)
    training.finish(out, model.eval(), config.to_json())
    return model
