"""Training the keypoint network on a synthetic image collection: `hsgplan train perception`.

Every (sample, view) image is one example; its targets are the belief maps and affinity fields
(`perception.maps.targets`) of the objects in sight in it (at least `MIN_VISIBLE` pixels), made
batch by batch. The loss is DOPE's: the mean
squared error of every stage's maps, summed over stages. Labels come from the renderer: the
poses the scene was staged in, projected through the camera that rendered it. The checkpoint
is a folder (`train_config.json`, `config.json`, `model.safetensors`, `manifest.json`) and a
run started again with the same configuration continues from its last saved epoch.
"""

from __future__ import annotations

import random
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import torch

from hsgplan import training
from hsgplan.checkpoint import fingerprint
from hsgplan.domain.checks import MAX_SEED, MAX_WORKERS, check_fields, from_settings, setting
from hsgplan.domain.errors import InvalidInputError
from hsgplan.perception.images import chunk_path, load_chunks
from hsgplan.perception.maps import targets
from hsgplan.perception.model import STRIDE, PerceptionNetConfig, build
from hsgplan.runner.run_folder import logged_rows

MIN_VISIBLE = 30  # pixels of an object in sight for its keypoints to be a target


@dataclass(frozen=True)
class PerceptionTrainConfig:
    images: str = "runs/collect-images"
    seed: int = setting(0, lo=0, hi=MAX_SEED)
    epochs: int = setting(8, lo=1, hi=10_000)
    lr: float = setting(1e-3, above=0, hi=10)
    batch_size: int = setting(16, lo=1, hi=4096)
    width: int = setting(32, lo=1, hi=512)
    stages: int = setting(2, lo=1, hi=6)
    save_every: int = setting(1, lo=1, hi=10_000)
    threads: int = setting(2, lo=1, hi=MAX_WORKERS)
    positive_weight: float = setting(0.0, lo=0, hi=10_000)  # see `loss_of`; 0 is DOPE's loss

    def __post_init__(self) -> None:
        check_fields(self)

    def net_config(self) -> PerceptionNetConfig:
        return PerceptionNetConfig(width=self.width, stages=self.stages)

    @staticmethod
    def from_json(d: dict) -> PerceptionTrainConfig:
        return from_settings(PerceptionTrainConfig, d)


@dataclass(frozen=True)
class Examples:
    """Every (sample, view) image with the keypoints and types of the objects in sight in it:
    images [E, 3, H, W] uint8; keypoints and types, E arrays of [M, 9, 2] and [M]. Targets are
    made per batch: kept for a whole collection they would take some 1.4 MB an image."""

    images: torch.Tensor
    keypoints: list[np.ndarray]
    types: list[np.ndarray]

    def targets(self, take: list[int], types_count: int) -> tuple[torch.Tensor, torch.Tensor]:
        """Belief maps and affinity fields of the images `take`: [B, C, h, w], [B, F, h, w]."""
        h, w = self.images.shape[2] // STRIDE, self.images.shape[3] // STRIDE
        maps = [targets(self.keypoints[i], self.types[i], types_count, h, w) for i in take]
        return (
            torch.from_numpy(np.stack([b for b, _ in maps])),
            torch.from_numpy(np.stack([f for _, f in maps])),
        )


def examples(data: dict[str, np.ndarray]) -> Examples:
    """Every (sample, view) of a loaded collection."""
    images, keypoints, types = [], [], []
    n, views = data["images"].shape[:2]
    for i in range(n):
        for v in range(views):
            seen = (data["types"][i] >= 0) & (data["visible"][i, v] >= MIN_VISIBLE)
            images.append(torch.from_numpy(data["images"][i, v]).permute(2, 0, 1))
            keypoints.append(data["keypoints"][i, v][seen])
            types.append(data["types"][i][seen].astype(np.int64))
    return Examples(torch.stack(images), keypoints, types)


def loss_of(
    outputs, beliefs: torch.Tensor, fields: torch.Tensor, positive_weight: float = 0.0
) -> torch.Tensor:
    """DOPE's loss: every stage's maps against the targets, mean squared error, summed. With
    `positive_weight` w, a belief cell's error weighs 1 + w x its target: the maps are almost
    all zeros, and unweighted the network first learns to predict nothing anywhere."""
    weight = 1.0 + positive_weight * beliefs
    return sum(
        (weight * (b - beliefs) ** 2).mean() + torch.nn.functional.mse_loss(f, fields)
        for b, f in outputs
    )


def train_perception(
    config: PerceptionTrainConfig,
    out: Path,
    on_epoch: Callable[[int, float], None] | None = None,
) -> None:
    """Train (or go on training) the keypoint network into the checkpoint folder `out`."""
    folder = Path(config.images)
    data = load_chunks(folder)  # a missing or damaged collection: refused before any write
    chunks = [chunk_path(folder, r["result"]["chunk"]) for r in logged_rows(folder)]
    data_print = fingerprint(chunks)
    training.claim(out, asdict(config))
    if training.finished(out):
        return
    net_config = config.net_config()
    found = examples(data)
    if len(found.images) == 0:
        raise InvalidInputError(f"no images in '{folder}'")
    torch.set_num_threads(config.threads)
    torch.manual_seed(config.seed)
    model = build(net_config)
    optim = torch.optim.Adam(model.parameters(), lr=config.lr)
    start = training.resume(out, model, optim, data_print)
    for epoch in range(start, config.epochs):
        model.train()
        order = list(range(len(found.images)))
        random.Random(f"{config.seed}-{epoch}").shuffle(order)
        total = 0.0
        for i in range(0, len(order), config.batch_size):
            take = order[i : i + config.batch_size]
            image = found.images[torch.tensor(take)].float() / 255.0
            beliefs, fields = found.targets(take, net_config.types)
            loss = loss_of(model(image), beliefs, fields, config.positive_weight)
            optim.zero_grad()
            loss.backward()
            optim.step()
            total += loss.detach().item() * len(take)
        training.check_loss(total, "the keypoint network", epoch + 1)
        if on_epoch:
            on_epoch(epoch + 1, total / len(order))
        if (epoch + 1) % config.save_every == 0 and epoch + 1 < config.epochs:
            training.save_progress(out, model, optim, epoch + 1, data_print)
    training.finish(out, model.eval(), net_config.to_json())
