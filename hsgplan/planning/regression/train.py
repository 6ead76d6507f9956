"""Training the task planner's networks: `hsgplan train task`.

Three edge classifiers are trained on the demonstrations, with cross-entropy: f_preimage
(don't care / true / false per slot), f_reach (no / yes per supervised slot) and the forward
baseline (the next subgoal). A checkpoint is a folder: `train_config.json`, and one folder per
network with `model.safetensors` and `config.json` (the network's configuration). Training saves
its progress (`progress.pt`, loaded with weights_only) every `save_every` epochs, and a run
started again with the same configuration continues from there.
"""

from __future__ import annotations

import json
import random
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path

import torch
from torch_geometric.data import Batch

from hsgplan import training
from hsgplan.domain.errors import InvalidInputError
from hsgplan.paths import DEMOS
from hsgplan.planning.regression.augment import trajectories
from hsgplan.planning.regression.encoding import EDGE_DIM, NODE_DIM
from hsgplan.planning.regression.examples import (
    Example,
    forward_examples,
    preimage_examples,
    reach_examples,
)
from hsgplan.planning.regression.gnn import (
    EdgeClassifier,
    EdgeClassifierConfig,
    masked_cross_entropy,
)

NETWORKS = {"preimage": 3, "reach": 2, "forward": 3}


@dataclass(frozen=True)
class TaskTrainConfig:
    demos: str = str(DEMOS)
    seed: int = 0
    epochs: int = 8
    lr: float = 1e-3
    batch_size: int = 32
    # the paper has 256 hidden units; 32 solved every size as well (README) and is faster
    hidden: int = 32
    rounds: int = 3
    save_every: int = 2
    copies: int = 20  # copies of each demonstration with added objects (`augment.py`)
    reach_singles: int = 12  # single-literal reach questions per state and label
    # f_reach learns from the first `reach_copies` copies only (None: all of them): its
    # examples are many per state, f_preimage's few
    reach_copies: int | None = None

    def __post_init__(self) -> None:
        for name in ("epochs", "batch_size", "hidden", "save_every", "reach_singles"):
            if not isinstance(getattr(self, name), int) or getattr(self, name) < 1:
                raise InvalidInputError(f"{name} {getattr(self, name)!r}: need a positive integer")
        for name in ("rounds", "copies"):
            if not isinstance(getattr(self, name), int) or getattr(self, name) < 0:
                raise InvalidInputError(f"{name} {getattr(self, name)!r}: cannot be negative")
        if self.reach_copies is not None and not 0 <= self.reach_copies <= self.copies:
            raise InvalidInputError(
                f"reach_copies {self.reach_copies!r}: between 0 and copies ({self.copies})"
            )

    @staticmethod
    def from_json(d: dict) -> TaskTrainConfig:
        unknown = set(d) - set(TaskTrainConfig.__dataclass_fields__)
        if unknown:
            raise InvalidInputError(f"unknown training setting(s): {', '.join(sorted(unknown))}")
        return TaskTrainConfig(**d)


def _examples(name: str, trajs, config: TaskTrainConfig) -> list[Example]:
    seed = config.seed
    if name == "reach":
        copies = config.copies if config.reach_copies is None else config.reach_copies
        n = len(trajs) // (config.copies + 1)  # the demonstrations, then copy after copy
        return reach_examples(trajs[: n * (1 + copies)], seed, config.reach_singles)
    if name == "preimage":
        return preimage_examples(trajs, seed)
    return forward_examples(trajs)


def train_task(
    config: TaskTrainConfig,
    out: Path,
    on_epoch: Callable[[str, int, float], None] | None = None,
) -> None:
    """Train (or go on training) the three networks into the checkpoint folder `out`."""
    from hsgplan.data.demos import load_demos

    demos = load_demos(Path(config.demos))
    out.mkdir(parents=True, exist_ok=True)
    saved = out / "train_config.json"
    if saved.exists() and json.loads(saved.read_text()) != asdict(config):
        raise InvalidInputError(f"'{out}' holds a checkpoint trained with another configuration")
    saved.write_text(json.dumps(asdict(config), indent=2) + "\n")
    trajs = trajectories(demos, config.copies, config.seed)
    for name, classes in NETWORKS.items():
        if (out / name / "model.safetensors").exists():
            continue  # finished earlier
        examples = _examples(name, trajs, config)
        _train_one(name, classes, examples, config, out / name, on_epoch)


def _train_one(name, classes, examples, config: TaskTrainConfig, folder: Path, on_epoch) -> None:
    folder.mkdir(exist_ok=True)
    if training.finished(folder):
        return  # finished earlier
    torch.manual_seed(config.seed)
    net_config = EdgeClassifierConfig(NODE_DIM, EDGE_DIM, 4, classes, config.hidden, config.rounds)
    model = EdgeClassifier(net_config)
    optim = torch.optim.Adam(model.parameters(), lr=config.lr)
    start = training.resume(folder, model, optim)
    data = [e.as_data() for e in examples]
    for epoch in range(start, config.epochs):
        rng = random.Random(f"{config.seed}-{name}-{epoch}")
        order = list(range(len(data)))
        rng.shuffle(order)
        total = 0.0
        for i in range(0, len(order), config.batch_size):
            batch = Batch.from_data_list([data[j] for j in order[i : i + config.batch_size]])
            loss = masked_cross_entropy(model(batch), batch.target, batch.mask)
            optim.zero_grad()
            loss.backward()
            optim.step()
            total += loss.detach().item() * batch.num_graphs
        if on_epoch:
            on_epoch(name, epoch + 1, total / len(data))
        if (epoch + 1) % config.save_every == 0 and epoch + 1 < config.epochs:
            training.save_progress(folder, model, optim, epoch + 1)
    training.finish(folder, model, net_config.to_json())
