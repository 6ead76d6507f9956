"""Training the task planner's networks: `hsgplan train task`.

Three edge classifiers are trained with cross-entropy: f_preimage (don't care / true / false per
slot) and the forward baseline (the next subgoal) on the demonstrations (and their copies with
added objects), f_reach (no / yes per supervised slot) on the labels its recipe names (see
`examples.py`). A checkpoint is a folder: `train_config.json`, and one folder per network with
`model.safetensors` and `config.json` (the network's configuration). Training saves its progress
(`progress.safetensors`) every `save_every` epochs, and a run started again
with the same configuration continues from there.
"""

from __future__ import annotations

import json
import random
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path

import torch
from torch_geometric.data import Batch

from hsgplan import training
from hsgplan.checkpoint import fingerprint
from hsgplan.data.world_trials import RESULTS, collection_worlds, load_world_trials
from hsgplan.domain.checks import BOUNDS, check_fields, from_settings, setting
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.scene import World
from hsgplan.files import write_atomically
from hsgplan.paths import DEMOS, REACH_DATA, shipped
from hsgplan.planning.regression.augment import trajectories
from hsgplan.planning.regression.encoding import with_features
from hsgplan.planning.regression.examples import (
    Example,
    forward_examples,
    paper_reach_examples,
    preimage_examples,
    world_reach_examples,
)
from hsgplan.planning.regression.features import check_features, edge_dim, node_dim, reads
from hsgplan.planning.regression.gnn import (
    EdgeClassifier,
    EdgeClassifierConfig,
    masked_cross_entropy,
)

NETWORKS = {"preimage": 3, "reach": 2, "forward": 3}
# f_reach's labels: "world" (executed primitives), "alterations" (the demonstrated changes and
# their alterations in subject, target or predicate), "predicates" (in the predicate alone)
REACH_SOURCES = ("world", "alterations", "predicates")


@dataclass(frozen=True)
class TaskTrainConfig:
    """How the task planner's networks are trained. The shipped checkpoints hold two recipes:
    `checkpoints/task-paper` (the paper's: the 18 demonstrations alone, f_reach from their
    alterations) and `checkpoints/task` (ours: copies with added objects, varied states,
    f_reach from primitives executed in the simulated world)."""

    demos: str = str(DEMOS)
    # the first this many demonstrations of the set (a point of a learning curve); None: all
    demo_limit: int | None = setting(None, lo=1, hi=1_000_000)
    seed: int = setting(0, **BOUNDS["seed"])
    epochs: int = setting(8, lo=1, hi=10_000)
    lr: float = setting(1e-3, above=0, hi=10)
    batch_size: int = setting(32, lo=1, hi=65_536)
    # the paper has 256 hidden units; 32 solved every size as well (README) and is faster
    hidden: int = setting(32, lo=1, hi=4096)
    rounds: int = setting(3, lo=0, hi=16)
    save_every: int = setting(2, lo=1, hi=10_000)
    # copies of each demonstration with added objects (`augment.py`); 0: none
    copies: int = setting(20, lo=0, hi=1000)
    vary: bool = True  # f_preimage also asked from varied states (`augment.varied`)
    reach: str = "world"  # f_reach's labels: one of REACH_SOURCES
    world_trials: str = str(REACH_DATA)  # the executed primitives, for reach = "world"
    # more executed primitives, from the states the agent visited (`collect visited`), for
    # reach = "world"; None: the staged states alone
    loop_trials: str | None = None
    # alterations asked alone per state and label (reach = "alterations" or "predicates")
    reach_singles: int = setting(12, lo=1, hi=1000)
    # for reach = "world", a seeded draw of this many of the executed primitives' examples
    # (None: all): a control as large as another recipe's f_reach, so that a ladder row can
    # change where the labels come from before a row adds more of them
    reach_limit: int | None = setting(None, lo=1, hi=100_000_000)
    # f_reach sees the max-pooled graph context (`gnn.RelationalLayer`): whether the hand is
    # full is news from an object nothing relates. f_preimage and the forward baseline do not:
    # a preimage is local, and with the pool f_preimage let crowded shelf tops elsewhere change
    # a push's preimage (measured: On(x, prepush_a) dropped from In(x, shelf_a)'s).
    reach_pool: bool = True
    # f_reach's epochs where they differ from `epochs`: world-labelled f_reach has two hundred
    # times the examples of the demonstrations alone
    reach_epochs: int | None = setting(None, lo=1, hi=10_000)
    # torch's threads: the graphs are small, and on 2 busy cores 2 threads trained f_preimage
    # about ten times slower than 1 (4.3 against 0.5 s an epoch on 36 demonstrations)
    threads: int = setting(1, **BOUNDS["workers"])
    # what a node is to the networks (`domain.scene.FEATURES`): its name, as the paper's, or what
    # the scene file says of it, so that the networks read scenes of other names
    features: str = "names"

    def __post_init__(self) -> None:
        check_fields(self)
        check_features(self.features)
        if self.reach not in REACH_SOURCES:
            raise InvalidInputError(f"reach {self.reach!r}: one of {', '.join(REACH_SOURCES)}")
        if self.reach_limit is not None and self.reach != "world":
            raise InvalidInputError("reach_limit draws from executed primitives: set reach 'world'")

    @staticmethod
    def from_json(d: dict) -> TaskTrainConfig:
        return from_settings(TaskTrainConfig, d)


def _examples(
    name: str, demos, trajs, config: TaskTrainConfig, world: World, home: World
) -> dict[str, list[Example]]:
    """A network's training examples by where their labels come from, in `world`; `home` is
    the world of data that records no scene."""
    n = len(demos)  # the demonstrations come first, then copy after copy
    if name == "reach":
        if config.reach == "predicates":
            return {
                "demonstrated changes and their other predicates": paper_reach_examples(
                    demos, config.seed, config.reach_singles, predicates_only=True
                )
            }
        if config.reach == "alterations":
            return {
                "demonstrated changes and their alterations": paper_reach_examples(
                    demos, config.seed, config.reach_singles
                )
            }
        names = (
            "primitives executed in the simulated world",
            "primitives executed from states the agent visited",
        )
        out = {
            name: world_reach_examples(
                load_world_trials(shipped(f), _trial_worlds(f, config.features, home)), []
            )
            for name, f in zip(names, _trial_folders(config), strict=False)
        }
        if config.reach_limit is not None:
            out = _drawn(out, config.reach_limit, config.seed)
        return out | {"demonstrated changes": world_reach_examples([], demos)}
    make = (
        (lambda t: preimage_examples(t, config.seed, config.vary))
        if name == "preimage"
        else forward_examples
    )
    out = {"demonstrations": make(trajs[:n])}
    if len(trajs) > n:
        out["copies with added objects"] = make(trajs[n:])
    return out


def _drawn(by_source: dict[str, list[Example]], limit: int, seed: int) -> dict[str, list[Example]]:
    """`limit` of the examples, drawn uniformly (seeded) across the sources, each source's
    kept in its order."""
    total = sum(len(ex) for ex in by_source.values())
    if limit > total:
        raise InvalidInputError(
            f"reach_limit {limit}: the executed primitives give {total} examples"
        )
    keep = set(random.Random(seed).sample(range(total), limit))
    out, start = {}, 0
    for name, ex in by_source.items():
        out[name] = [e for i, e in enumerate(ex, start) if i in keep]
        start += len(ex)
    return out


def _trial_folders(config: TaskTrainConfig) -> list[str]:
    """The collections of executed primitives f_reach learns from: the staged, then the visited."""
    return [config.world_trials] + ([config.loop_trials] if config.loop_trials else [])


def _trial_worlds(folder: str, features: str, home: World) -> list[World]:
    """The worlds a collection of f_reach's executed primitives was staged in. Each state is
    described in its own (`Example.world`), which need not be the demonstrations': f_reach may
    learn round other layouts. InvalidInputError for a folder holding no collection, or worlds
    the networks' features cannot read."""
    worlds = collection_worlds(shipped(folder), home)
    unread = sorted({w.name for w in worlds if not reads(features, w)})
    if unread:
        raise InvalidInputError(
            f"'{folder}' was collected in scenes of other groceries than the "
            f"kitchen's ({', '.join(unread)}); networks of features names know the "
            "kitchen's names alone: train with features geometry"
        )
    if not (shipped(folder) / RESULTS).is_file():
        raise InvalidInputError(f"'{folder}' holds no collection of executed primitives")
    return worlds


def label_counts(examples: list[Example]) -> dict:
    """How many examples, supervised slots, and slots of each class a list holds."""
    slots = [e.target[e.mask] for e in examples]
    counts = torch.bincount(torch.cat(slots), minlength=2) if slots else torch.zeros(2)
    return {
        "examples": len(examples),
        "labels": int(counts.sum()),
        "by_class": [int(c) for c in counts],
    }


def train_task(
    config: TaskTrainConfig,
    out: Path,
    on_epoch: Callable[[str, int, float], None] | None = None,
    *,
    world: World,
    networks: Sequence[str] = tuple(NETWORKS),
    claimed: bool = False,
) -> None:
    """Train (or go on training) the networks (`networks`, by default all three) into the
    checkpoint folder `out` on the demonstrations (and executed primitives) recorded in
    `world`, or in the scene file they were recorded in (`collect demos --scene`, `collect
    reach --scene`). The executed primitives may come from other worlds than the
    demonstrations (a folder of layouts): each state is described in its own. Each network's
    folder gets `labels.json`, its label counts by source. With `claimed`, another process
    claimed `out` (`claim_task`) and this one holds only the networks' folders it trains: the
    networks of one checkpoint train side by side, each as it would alone."""
    home, world, demos, data = _prepared(config, world)
    if not claimed:
        claim_task(config, out, home)
    trajs = trajectories(demos, config.copies, config.seed)
    torch.set_num_threads(config.threads)
    for name in networks:
        if training.finished(out / name):
            continue  # finished earlier
        if claimed:
            training.hold(out / name)
        by_source = _examples(name, demos, trajs, config, world, home)
        (out / name).mkdir(exist_ok=True)
        counts = {source: label_counts(ex) for source, ex in by_source.items()}
        write_atomically(out / name / "labels.json", json.dumps(counts, indent=2) + "\n")
        examples = [e for ex in by_source.values() for e in ex]
        _train_one(name, NETWORKS[name], examples, config, out / name, on_epoch, data, world)


def claim_task(config: TaskTrainConfig, out: Path, world: World) -> None:
    """Make `out` the checkpoint folder of a task training with `config`, refused in one line
    before anything is trained (a bad dataset, another configuration's checkpoint)."""
    data = _prepared(config, world)[3]
    # a checkpoint trained before a setting existed was trained with its default
    training.claim(out, asdict(config), defaults=asdict(TaskTrainConfig()), data=data)


def _prepared(config: TaskTrainConfig, world: World) -> tuple[World, World, list, str]:
    """The world of data that records no scene, the demonstrations' world, the demonstrations
    and the training data's fingerprint; bad data refused before anything is written."""
    from hsgplan.data.demos import demos_world, load_demos

    home, world = world, demos_world(Path(config.demos), world)
    demos = load_demos(Path(config.demos), world)
    if config.demo_limit is not None:
        if config.demo_limit > len(demos):
            raise InvalidInputError(
                f"demo_limit {config.demo_limit}: '{config.demos}' holds {len(demos)} "
                "demonstrations"
            )
        demos = demos[: config.demo_limit]
    if config.reach == "world":
        for folder in _trial_folders(config):  # refused before anything is trained or written
            _trial_worlds(folder, config.features, home)
    sources = [config.demos] + (_trial_folders(config) if config.reach == "world" else [])
    return home, world, demos, fingerprint(Path(s) for s in sources)


def _train_one(
    name,
    classes,
    examples,
    config: TaskTrainConfig,
    folder: Path,
    on_epoch,
    data: str,
    world: World,
) -> None:
    folder.mkdir(exist_ok=True)
    if training.finished(folder):
        return  # finished earlier
    torch.manual_seed(config.seed)
    net_config = EdgeClassifierConfig(
        node_dim(config.features),
        edge_dim(config.features),
        4,
        classes,
        config.hidden,
        config.rounds,
        name == "reach" and config.reach_pool,
        config.features,
    )
    model = EdgeClassifier(net_config)
    optim = torch.optim.Adam(model.parameters(), lr=config.lr)
    start = training.resume(folder, model, optim, data)
    graphs = [with_features(e.as_data(), e.world or world, config.features) for e in examples]
    epochs = config.reach_epochs if name == "reach" and config.reach_epochs else config.epochs
    for epoch in range(start, epochs):
        rng = random.Random(f"{config.seed}-{name}-{epoch}")
        order = list(range(len(graphs)))
        rng.shuffle(order)
        total = 0.0
        for i in range(0, len(order), config.batch_size):
            batch = Batch.from_data_list([graphs[j] for j in order[i : i + config.batch_size]])
            loss = masked_cross_entropy(model(batch), batch.target, batch.mask)
            optim.zero_grad()
            loss.backward()
            optim.step()
            total += loss.detach().item() * batch.num_graphs
        training.check_loss(total, name, epoch + 1)
        if on_epoch:
            on_epoch(name, epoch + 1, total / len(graphs))
        if (epoch + 1) % config.save_every == 0 and epoch + 1 < epochs:
            training.save_progress(folder, model, optim, epoch + 1, data)
    training.finish(folder, model, net_config.to_json())
