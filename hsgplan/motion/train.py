"""Training a motion network on the collected successes: `hsgplan train motion`.

Two losses. `ce`, the paper's: cross-entropy over the joint bin pair of each successful trial,
so the network learns which bins succeed in a scene like this one. `bce` (beyond the paper):
every trial, failures included, teaches the logit of its own bin pair whether it succeeded, so
the network estimates each bin's chance of success from more than twice the data. The
checkpoint is a folder: `train_config.json`, `config.json` (the network's), `model.safetensors`;
`progress.safetensors` holds the last finished epoch while training runs, so
that a run started again with the same configuration continues from there. With a
validation share, `training.json` says how many examples trained it, how many chose its
epoch, the loss of every epoch and the epoch kept.
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
from hsgplan.checkpoint import fingerprint
from hsgplan.data.motion_store import MotionData, load_dataset
from hsgplan.domain.checks import (
    BOUNDS,
    check_fields,
    from_settings,
    read_json,
    setting,
)
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.parameters import BINS, MotionPrimitive
from hsgplan.domain.predicates import inside, on
from hsgplan.files import write_atomically
from hsgplan.motion.models import MotionNetConfig, build
from hsgplan.paths import MOTION_DATA, shipped
from hsgplan.scene_graph.grounding import dims, ground
from hsgplan.scene_graph.names import unnamed
from hsgplan.training import TRAIN_CONFIG


@dataclass(frozen=True)
class MotionTrainConfig:
    primitive: str = "place"
    model: str = "gnn"
    data: str = str(MOTION_DATA)
    seed: int = setting(0, **BOUNDS["seed"])
    epochs: int = setting(40, lo=1, hi=10_000)
    lr: float = setting(1e-3, above=0, hi=10)
    batch_size: int = setting(64, lo=1, hi=65_536)
    hidden: int = setting(256, lo=1, hi=4096)  # the paper's widths
    embed: int = setting(32, lo=1, hi=1024)
    rounds: int = setting(2, lo=0, hi=16)
    save_every: int = setting(5, lo=1, hi=10_000)
    # the first this many samples of the dataset (None: all)
    samples: int | None = setting(None, **BOUNDS["samples"])
    # with bce, the first this many of its trials (None: every trial up to the last success
    # kept): a control as large as the successes ce learns from, so that a ladder row can
    # change the loss alone before a row adds the failed trials
    trials: int | None = setting(None, **BOUNDS["samples"])
    # The networks are small: measured on 2 busy cores, 2 threads trained ten times slower
    # than 1 (they fight the simulation workers for the cores).
    threads: int = setting(1, **BOUNDS["workers"])
    loss: str = "ce"  # "ce" (successes, the paper's) or "bce" (every trial)
    # "mlp" or "per-dim" (the paper's, read jointly or per dimension: `models`) or "bins"
    # (`models.BinQueryHead`, `FlatBinHead`)
    head: str = "mlp"
    # The share of the training scenes held out to choose the epoch: the weights kept are
    # those of the epoch with the lowest loss on them (0: train on all, keep the last epoch).
    validation: float = setting(0.0, lo=0, hi=0.5)
    # regularisation, none by default (the paper's): dropout after every hidden layer of the
    # networks' MLPs, and decoupled weight decay (AdamW in place of Adam)
    dropout: float = setting(0.0, lo=0, hi=0.9)
    weight_decay: float = setting(0.0, lo=0, hi=1)
    # what a node is (`domain.scene.FEATURES`): "names" (the paper's) or "geometry"
    features: str = "names"

    def __post_init__(self) -> None:
        check_fields(self)
        if self.primitive not in ("place", "push"):
            raise InvalidInputError(f"primitive '{self.primitive}': place or push")
        if self.loss not in ("ce", "bce"):
            raise InvalidInputError(f"loss '{self.loss}': ce or bce")
        if self.head == "per-dim" and self.loss != "ce":
            # its scores are log-probabilities: no logit of a pair's own success to teach
            raise InvalidInputError("head 'per-dim' learns with loss 'ce' only")
        if self.trials is not None and self.loss != "bce":
            raise InvalidInputError("trials counts what loss 'bce' learns from: set loss 'bce'")
        self.net_config()  # refuses a bad model name or width

    def net_config(self) -> MotionNetConfig:
        bins = BINS[MotionPrimitive(self.primitive)]
        node_dim, subgoal_dim = dims(self.features)
        return MotionNetConfig(
            self.model,
            self.primitive,
            bins,
            self.hidden,
            self.embed,
            self.rounds,
            node_dim=node_dim,
            subgoal_dim=subgoal_dim,
            head=self.head,
            features=self.features,
            dropout=self.dropout,
        )

    @staticmethod
    def from_json(d: dict) -> MotionTrainConfig:
        return from_settings(MotionTrainConfig, d)


def _training_rows(config: MotionTrainConfig) -> MotionData:
    """The first `samples` successes, and with `bce` every trial up to the last of them (the
    first `trials` of those)."""
    folder = shipped(config.data)
    primitive = MotionPrimitive(config.primitive)
    data = load_dataset(folder / f"{config.primitive}.npz", primitive)
    if config.samples is not None:
        if config.samples > len(data):
            raise InvalidInputError(
                f"samples {config.samples}: '{folder}' holds {len(data)} successful "
                f"{config.primitive} samples"
            )
        data = data.take(slice(0, config.samples))
    if len(data) == 0:
        raise InvalidInputError(f"no successful {config.primitive} samples in '{folder}'")
    others = unnamed(data.world)
    if config.features == "names" and others:
        raise InvalidInputError(
            f"'{folder}' was collected in a scene that names others than the kitchen "
            f"({', '.join(others)}); networks of features names know the kitchen's names "
            "alone: train with features geometry"
        )
    if config.loss == "ce":
        return data
    trials = load_dataset(folder / f"{config.primitive}_trials.npz", primitive)
    last = (int(data.task[-1]), int(data.attempt[-1]))
    keep = [(int(t), int(a)) <= last for t, a in zip(trials.task, trials.attempt, strict=True)]
    kept = trials.take(np.array(keep, dtype=bool))
    if config.trials is None:
        return kept
    if config.trials > len(kept):
        raise InvalidInputError(
            f"trials {config.trials}: the first {len(data)} successes in '{folder}' come with "
            f"{len(kept)} {config.primitive} trials"
        )
    return kept.take(slice(0, config.trials))


def _loss(kind: str, model: torch.nn.Module, batch) -> torch.Tensor:
    if kind == "ce":
        return torch.nn.functional.cross_entropy(model(batch), batch.y)
    # Each trial teaches its own bin pair's logit only: the others need not be scored.
    picked = model(batch, only=batch.y).squeeze(1)
    return torch.nn.functional.binary_cross_entropy_with_logits(picked, batch.ok.float())


def grounded_examples(data: MotionData, features: str = "names") -> list[Data]:
    """Every row grounded for its subgoal, labelled with its flattened bin pair and whether
    the trial succeeded."""
    ny = BINS[data.primitive][1]
    subgoal = on if data.primitive is MotionPrimitive.PLACE else inside
    out = []
    for i in range(len(data)):
        lit = subgoal(data.object_name(i), data.target_name(i))
        g = ground(data.scene_graph(i), lit, features)
        g.y = torch.tensor([int(data.bins[i, 0]) * ny + int(data.bins[i, 1])])
        g.ok = torch.tensor([bool(data.ok[i])])
        out.append(g)
    return out


SELECTION = "training.json"  # the examples and the epoch kept, beside a checkpoint


def split_tasks(data: MotionData, share: float, seed: int) -> np.ndarray:
    """Which rows are held out: every trial of `share` of the tasks (scenes), drawn with
    `seed`, so that no held-out scene was also trained on."""
    tasks = np.unique(data.task)
    count = int(round(share * len(tasks)))
    held = np.random.default_rng(seed).permutation(tasks)[:count]
    return np.isin(data.task, held)


def _mean_loss(kind: str, model: torch.nn.Module, examples: list[Data], size: int) -> float:
    total = 0.0
    model.eval()  # no dropout while the held-out loss is read
    with torch.no_grad():
        for i in range(0, len(examples), size):
            batch = Batch.from_data_list(examples[i : i + size])
            total += _loss(kind, model, batch).item() * batch.num_graphs
    model.train()
    return total / len(examples)


def train_motion(
    config: MotionTrainConfig,
    out: Path,
    on_epoch: Callable[[int, float], None] | None = None,
) -> None:
    """Train (or go on training) one motion network into the checkpoint folder `out`."""
    rows = _training_rows(config)  # a missing or damaged dataset: refused before any write
    folder = shipped(config.data)
    files = [folder / f"{config.primitive}.npz"]
    if config.loss == "bce":
        files.append(folder / f"{config.primitive}_trials.npz")
    data = fingerprint(files)
    # settings a folder trained before they existed was trained with: their defaults
    defaults = {"features": "names", "dropout": 0.0, "weight_decay": 0.0, "trials": None}
    training.claim(out, asdict(config), defaults=defaults, data=data)
    if training.finished(out):
        return  # finished earlier
    held = split_tasks(rows, config.validation, config.seed)
    examples = grounded_examples(rows.take(~held), config.features)
    checking = grounded_examples(rows.take(held), config.features)
    torch.set_num_threads(config.threads)
    torch.manual_seed(config.seed)
    net_config = config.net_config()
    model = build(net_config)
    if config.weight_decay > 0:
        optim = torch.optim.AdamW(
            model.parameters(), lr=config.lr, weight_decay=config.weight_decay
        )
    else:  # Adam, as every network trained before the setting was
        optim = torch.optim.Adam(model.parameters(), lr=config.lr)
    start, kept = training.resume_with(out, model, optim, data)
    history: list[dict] = list(kept.get("history", []))
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
        training.check_loss(total, f"the {config.model} {config.primitive} network", epoch + 1)
        row = {"epoch": epoch + 1, "loss": total / len(examples)}
        if checking:
            row["validation_loss"] = _mean_loss(config.loss, model, checking, 512)
            best = min((h["validation_loss"] for h in history), default=float("inf"))
            if row["validation_loss"] < best:
                kept["best"] = {k: v.clone() for k, v in model.state_dict().items()}
        history.append(row)
        if on_epoch:
            on_epoch(epoch + 1, row["loss"])
        if (epoch + 1) % config.save_every == 0 and epoch + 1 < config.epochs:
            extra = {"history": history, **({"best": kept["best"]} if "best" in kept else {})}
            training.save_progress(out, model, optim, epoch + 1, data, extra)
    if checking:
        model.load_state_dict(kept["best"])
        chosen = min(history, key=lambda h: h["validation_loss"])["epoch"]
        selection = {
            "training_examples": len(examples),
            "validation_examples": len(checking),
            "chosen_epoch": chosen,
            "rule": "the epoch of lowest validation loss",
            "epochs": history,
        }
        write_atomically(out / SELECTION, json.dumps(selection, indent=2) + "\n")
    training.finish(out, model, net_config.to_json())


@dataclass(frozen=True)
class TrainingRecord:
    """What a motion checkpoint was trained on: its examples, the examples that chose its
    epoch, and the epoch kept (the last, where none were held out)."""

    parameters: int
    training_examples: int
    validation_examples: int
    chosen_epoch: int

    @staticmethod
    def of(folder: Path, model: torch.nn.Module) -> TrainingRecord:
        parameters = sum(p.numel() for p in model.parameters())
        if (folder / SELECTION).is_file():
            saved = read_json(folder / SELECTION, "training record")
            return TrainingRecord(
                parameters,
                int(saved["training_examples"]),
                int(saved["validation_examples"]),
                int(saved["chosen_epoch"]),
            )
        config = MotionTrainConfig.from_json(
            read_json(folder / TRAIN_CONFIG, "training configuration")
        )
        return TrainingRecord(parameters, len(_training_rows(config)), 0, config.epochs)
