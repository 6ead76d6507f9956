"""Training a motion network on the collected successes: `hsgplan train motion`.

Two losses. `ce`, the paper's: cross-entropy over the joint bin pair of each successful trial,
so the network learns which bins succeed in a scene like this one. `bce` (beyond the paper):
every trial, failures included, teaches the logit of its own bin pair whether it succeeded, so
the network estimates each bin's chance of success from more than twice the data. The
checkpoint is a folder: `train_config.json`, `config.json` (the network's), `model.safetensors`;
`progress.pt` (loaded with weights_only) holds the last finished epoch while training runs, so
that a run started again with the same configuration continues from there.
"""

from __future__ import annotations

import json
import random
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import torch
from torch_geometric.data import Batch, Data

from hsgplan import training
from hsgplan.data.motion_store import MotionData, load
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.parameters import BINS, MotionPrimitive
from hsgplan.domain.predicates import inside, on
from hsgplan.motion.models import MotionNetConfig, build
from hsgplan.paths import MOTION_DATA, shipped
from hsgplan.scene_graph.grounding import ground


@dataclass(frozen=True)
class MotionTrainConfig:
    primitive: str = "place"
    model: str = "gnn"
    data: str = str(MOTION_DATA)
    seed: int = 0
    epochs: int = 40
    lr: float = 1e-3
    batch_size: int = 64
    hidden: int = 256  # the paper's widths
    embed: int = 32
    rounds: int = 2
    save_every: int = 5
    samples: int | None = None  # the first this many samples of the dataset (None: all)
    # The networks are small: measured on 2 busy cores, 2 threads trained ten times slower
    # than 1 (they fight the simulation workers for the cores).
    threads: int = 1
    loss: str = "ce"  # "ce" (successes, the paper's) or "bce" (every trial)
    head: str = "mlp"  # the GNN's head: "mlp" (the paper's) or "bins" (`models.BinQueryHead`)

    def __post_init__(self) -> None:
        if self.primitive not in ("place", "push"):
            raise InvalidInputError(f"primitive '{self.primitive}': place or push")
        for name in ("epochs", "batch_size", "save_every", "threads"):
            if not isinstance(getattr(self, name), int) or getattr(self, name) < 1:
                raise InvalidInputError(f"{name} {getattr(self, name)!r}: need a positive integer")
        if self.loss not in ("ce", "bce"):
            raise InvalidInputError(f"loss '{self.loss}': ce or bce")
        if self.samples is not None and self.samples < 1:
            raise InvalidInputError(f"samples {self.samples!r}: need a positive integer or null")
        self.net_config()  # refuses a bad model name or width

    def net_config(self) -> MotionNetConfig:
        bins = BINS[MotionPrimitive(self.primitive)]
        return MotionNetConfig(
            self.model, self.primitive, bins, self.hidden, self.embed, self.rounds, head=self.head
        )

    @staticmethod
    def from_json(d: dict) -> MotionTrainConfig:
        unknown = set(d) - set(MotionTrainConfig.__dataclass_fields__)
        if unknown:
            raise InvalidInputError(f"unknown training setting(s): {', '.join(sorted(unknown))}")
        return MotionTrainConfig(**d)


def _training_rows(config: MotionTrainConfig) -> MotionData:
    """The first `samples` successes, and with `bce` every trial up to the last of them."""
    folder = shipped(config.data)
    data = load(folder / f"{config.primitive}.npz")
    if config.samples is not None:
        data = data.take(slice(0, config.samples))
    if len(data) == 0:
        raise InvalidInputError(f"no successful {config.primitive} samples in '{folder}'")
    if config.loss == "ce":
        return data
    trials = load(folder / f"{config.primitive}_trials.npz")
    last = (int(data.task[-1]), int(data.attempt[-1]))
    keep = [(int(t), int(a)) <= last for t, a in zip(trials.task, trials.attempt, strict=True)]
    return trials.take(np.array(keep, dtype=bool))


def _loss(kind: str, model: torch.nn.Module, batch) -> torch.Tensor:
    if kind == "ce":
        return torch.nn.functional.cross_entropy(model(batch), batch.y)
    # Each trial teaches its own bin pair's logit only: the others need not be scored.
    picked = model(batch, only=batch.y).squeeze(1)
    return torch.nn.functional.binary_cross_entropy_with_logits(picked, batch.ok.float())


def grounded_examples(data: MotionData) -> list[Data]:
    """Every row grounded for its subgoal, labelled with its flattened bin pair and whether
    the trial succeeded."""
    ny = BINS[data.primitive][1]
    subgoal = on if data.primitive is MotionPrimitive.PLACE else inside
    out = []
    for i in range(len(data)):
        g = ground(data.scene_graph(i), subgoal(data.object_name(i), data.target_name(i)))
        g.y = torch.tensor([int(data.bins[i, 0]) * ny + int(data.bins[i, 1])])
        g.ok = torch.tensor([bool(data.ok[i])])
        out.append(g)
    return out


def train_motion(
    config: MotionTrainConfig,
    out: Path,
    on_epoch: Callable[[int, float], None] | None = None,
) -> None:
    """Train (or go on training) one motion network into the checkpoint folder `out`."""
    out.mkdir(parents=True, exist_ok=True)
    saved = out / "train_config.json"
    if saved.exists() and json.loads(saved.read_text()) != asdict(config):
        raise InvalidInputError(f"'{out}' holds a checkpoint trained with another configuration")
    saved.write_text(json.dumps(asdict(config), indent=2) + "\n")
    if training.finished(out):
        return  # finished earlier
    examples = grounded_examples(_training_rows(config))
    torch.set_num_threads(config.threads)
    torch.manual_seed(config.seed)
    net_config = config.net_config()
    model = build(net_config)
    optim = torch.optim.Adam(model.parameters(), lr=config.lr)
    start = training.resume(out, model, optim)
    for epoch in range(start, config.epochs):
        order = list(range(len(examples)))
        random.Random(f"{config.seed}-{epoch}").shuffle(order)
        total = 0.0
        for i in range(0, len(order), config.batch_size):
            batch = Batch.from_data_list([examples[j] for j in order[i : i + config.batch_size]])
            loss = _loss(config.loss, model, batch)
            optim.zero_grad()
            loss.backward()
            optim.step()
            total += loss.detach().item() * batch.num_graphs
        if on_epoch:
            on_epoch(epoch + 1, total / len(examples))
        if (epoch + 1) % config.save_every == 0 and epoch + 1 < config.epochs:
            training.save_progress(out, model, optim, epoch + 1)
    training.finish(out, model, net_config.to_json())
