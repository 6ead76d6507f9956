"""Training the keypoint network on a synthetic image collection: `hsgplan train perception`.

Every (sample, view) image is one example; its targets are the belief maps and affinity fields
(`perception.maps.targets`) of the objects in sight in it (at least `MIN_VISIBLE` pixels), made
once per image and kept in memory at the output resolution. The loss is DOPE's: the mean
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

    def __post_init__(self) -> None:
        check_fields(self)

    def net_config(self) -> PerceptionNetConfig:
        return PerceptionNetConfig(width=self.width, stages=self.stages)

    @staticmethod
    def from_json(d: dict) -> PerceptionTrainConfig:
        return from_settings(PerceptionTrainConfig, d)


@dataclass(frozen=True)
class Examples:
    """Images and their targets: images [E, 3, H, W] uint8; beliefs [E, C, h, w] float16;
    fields [E, F, h, w] float16."""

    images: torch.Tensor
    beliefs: torch.Tensor
    fields: torch.Tensor


def examples(data: dict[str, np.ndarray], types_count: int) -> Examples:
    """Every (sample, view) of a loaded collection with its targets."""
    images, beliefs, fields = [], [], []
    n, views, height, width = data["images"].shape[:4]
    h, w = height // STRIDE, width // STRIDE
    for i in range(n):
        for v in range(views):
            seen = (data["types"][i] >= 0) & (data["visible"][i, v] >= MIN_VISIBLE)
            b, f = targets(data["keypoints"][i, v][seen], data["types"][i][seen], types_count, h, w)
            images.append(torch.from_numpy(data["images"][i, v]).permute(2, 0, 1))
            beliefs.append(torch.from_numpy(b).half())
            fields.append(torch.from_numpy(f).half())
    return Examples(torch.stack(images), torch.stack(beliefs), torch.stack(fields))


def loss_of(outputs, beliefs: torch.Tensor, fields: torch.Tensor) -> torch.Tensor:
    """DOPE's loss: every stage's maps against the targets, mean squared error, summed."""
    return sum(
        torch.nn.functional.mse_loss(b, beliefs) + torch.nn.functional.mse_loss(f, fields)
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
    found = examples(data, net_config.types)
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
            take = torch.tensor(order[i : i + config.batch_size])
            image = found.images[take].float() / 255.0
            loss = loss_of(model(image), found.beliefs[take].float(), found.fields[take].float())
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
