"""Commands of the motion level: `train motion`, `eval motion`."""

from __future__ import annotations

import json
import re
from dataclasses import replace
from enum import StrEnum
from pathlib import Path
from typing import Annotated

import typer
from rich.progress import Progress

from hsgplan.cli.common import (
    CollectWorkers,
    MarkdownFlag,
    RayAddress,
    SceneFiles,
    bounded_option,
    check_ray,
    default_networks,
    err,
    input_path,
    out,
    out_folder,
    print_table,
    read_config,
    refuses_bad_input,
    shown,
)
from hsgplan.cli.seeding import SplitOption, TrainingSeeds, split_seed
from hsgplan.domain.errors import InvalidInputError
from hsgplan.paths import MOTION_CHECKPOINTS, RUNS


class Primitive(StrEnum):
    place = "place"
    push = "push"


class Model(StrEnum):
    gnn = "gnn"
    mlp = "mlp"


_FOLDER_NAME = re.compile(r"^[A-Za-z0-9_-]+$")


@refuses_bad_input
def train_motion(
    primitive: Annotated[
        Primitive | None, typer.Option(help="place or push (default: the config's, or place).")
    ] = None,
    model: Annotated[
        Model | None, typer.Option(help="gnn or mlp (default: the config's, or gnn).")
    ] = None,
    config: Annotated[
        list[Path] | None,
        typer.Option(
            help="Training configuration (JSON); with --seeds, repeat it for several networks "
            "trained together.",
            parser=input_path,
            metavar="FILE",
        ),
    ] = None,
    out_dir: Annotated[
        Path | None,
        typer.Option(
            "--out",
            help="Checkpoint folder (default: runs/train-motion-PRIMITIVE-MODEL; a shipped "
            "checkpoint is never written unless named).",
            parser=out_folder,
        ),
    ] = None,
    data: Annotated[
        Path | None,
        typer.Option(help="Dataset folder (overrides the config).", parser=input_path),
    ] = None,
    seeds: TrainingSeeds = None,
    workers: Annotated[
        int, bounded_option("workers", "With --seeds, trainings run side by side.")
    ] = 1,
    name: Annotated[
        str | None,
        typer.Option(
            help="With --seeds, the network's folder in each OUT/seed-S (default: PRIMITIVE-MODEL)."
        ),
    ] = None,
) -> None:
    """Train a motion network (config loss: ce on the successes, bce on every trial); with
    --seeds and several --config, every network of every seed in one pool of workers."""
    from hsgplan.trainings import record, seed_folder, train_each, training_seeds

    configs = config or [None]
    if len(configs) > 1 and (seeds is None or name or primitive or model):
        raise InvalidInputError(
            "several --config: with --seeds, and without --name, --primitive or --model "
            "(each network is named PRIMITIVE-MODEL by its configuration)"
        )
    cfgs = [_motion_config(c, primitive, model, data) for c in configs]
    if name is not None and (seeds is None or not _FOLDER_NAME.match(name)):
        raise InvalidInputError(
            f"--name '{name}': a folder name (letters, digits, - and _), with --seeds"
        )
    named = [name or f"{c.primitive}-{c.model}" for c in cfgs]
    if len(set(named)) < len(named):
        raise InvalidInputError(f"two --config train the same network ({', '.join(named)})")
    first = cfgs[0]
    folder = out_dir or RUNS / f"train-motion-{first.primitive}-{first.model}"
    if seeds is None:
        _train_motion_once(first, folder)
        out.print(f"trained the {first.model} {first.primitive} network into {shown(folder)}")
        return
    trained = []  # (config, seeds, folders) of each network
    for cfg, network in zip(cfgs, named, strict=True):
        every = training_seeds(cfg.seed, seeds)
        trained.append((cfg, every, [seed_folder(folder, s) / network for s in every]))
    jobs = [
        (replace(cfg, seed=s), f)
        for cfg, every, into in trained
        for s, f in zip(every, into, strict=True)
    ]
    train_each(_train_motion_once, jobs, workers)
    for cfg, every, into in trained:
        record(folder, every, into[0].name)
        for f in into:
            out.print(f"trained the {cfg.model} {cfg.primitive} network into {shown(f)}")


def _motion_config(config: Path | None, primitive, model, data: Path | None):
    """A motion training configuration from its file, the command's overrides applied."""
    from hsgplan.motion.train import MotionTrainConfig

    settings = read_config(config)
    for option, given in (("primitive", primitive), ("model", model)):
        if given is not None and settings.get(option, given.value) != given.value:
            raise InvalidInputError(
                f"--{option} {given.value}: the configuration '{config}' trains "
                f"{option} {settings[option]!r}"
            )
        if given is not None:
            settings[option] = given.value
    cfg = MotionTrainConfig.from_json(settings)
    return cfg if data is None else replace(cfg, data=str(data))


def _train_motion_once(cfg, into: Path, show: bool = True) -> None:
    from hsgplan.motion.train import train_motion as run

    if not show:
        run(cfg, into, None)
        return
    with Progress(console=err, transient=True) as progress:
        bar = progress.add_task(f"{cfg.primitive} {cfg.model}", total=cfg.epochs)

        def on_epoch(epoch: int, loss: float) -> None:
            progress.update(
                bar, completed=epoch, description=f"{cfg.primitive} {cfg.model} loss {loss:.3f}"
            )

        run(cfg, into, on_epoch)


def _rate_cell(r: dict) -> str:
    cell = f"{r['success_rate']:.3f}"
    if r.get("success_ci"):
        cell += f" ({r['success_ci'][0]:.2f}–{r['success_ci'][1]:.2f})"
    return cell


@refuses_bad_input
def eval_motion(
    trials: Annotated[int, bounded_option("trials", "Fresh scenes per primitive.")] = 200,
    seed: Annotated[
        int | None,
        bounded_option("seed", "Seed of the evaluation scenes (default: 0, or the split's first)."),
    ] = None,
    split: SplitOption = None,
    primitives: Annotated[str, typer.Option(help="place, push or place,push.")] = "place,push",
    motion_checkpoints: Annotated[
        Path | None,
        typer.Option(
            help="Folder of motion checkpoints (default: the shipped checkpoints/motion).",
            parser=input_path,
        ),
    ] = None,
    workers: CollectWorkers = 2,
    ray: RayAddress = None,
    run_dir: Annotated[
        Path | None,
        typer.Option(
            "--out",
            help="Run folder (resumed if it exists); none: nothing is kept.",
            parser=out_folder,
        ),
    ] = None,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print one JSON object.", metavar="")
    ] = False,
    markdown: MarkdownFlag = False,
    scene: SceneFiles = None,
) -> None:
    """Single-shot success of the GNN, the MLP and Random on fresh random scenes (never the
    training scenes), per primitive and crowding level; every model sees the same scenes."""
    from hsgplan.domain.scene_file import default_world, read_worlds
    from hsgplan.evaluation.motion_eval import LABELS, MODELS, evaluate_motion
    from hsgplan.evaluation.seeds import marked, seed_words
    from hsgplan.evaluation.splits import check_seed, split_named
    from hsgplan.trainings import seed_folders

    kinds = [p.strip() for p in primitives.split(",")]
    if "" in kinds or len(set(kinds)) != len(kinds):
        raise InvalidInputError(f"--primitives '{primitives}': name place, push or both, each once")
    check_ray(ray)
    seed = split_seed(seed, split)
    if split is not None:
        check_seed(split_named(split.value), seed)
    worlds = list(read_worlds(scene).values()) if scene else [default_world()]
    # the motion networks alone: fd reads no network, so only the motion folder may be swapped
    _, given = default_networks("fd+gnn", worlds, None, motion_checkpoints)
    motion_checkpoints = given or MOTION_CHECKPOINTS
    trainings = seed_folders(motion_checkpoints)
    with Progress(console=err, transient=True) as progress:
        bar = progress.add_task("scenes", total=trials * len(kinds) * len(worlds))
        report = evaluate_motion(
            kinds,
            trials,
            seed,
            motion_checkpoints,
            workers,
            lambda: progress.advance(bar),
            run_dir,
            ray,
            scene,
        )
    if as_json:
        print(json.dumps(report, indent=2))
        return
    rows = []
    for kind, by_model in report.items():
        levels = sorted({lvl for m in by_model.values() for lvl in m["by_crowding"]})
        picks = {"all": lambda r: r} | {
            lvl: (lambda r, lvl=lvl: r["by_crowding"].get(lvl)) for lvl in levels
        }
        picks["crowded shelf tops"] = lambda r: r.get("crowded_shelf_tops")
        for label, pick in picks.items():
            found = [pick(by_model[m]) if m in by_model else None for m in MODELS]
            if all(r is None for r in found):
                continue
            cells = ["—" if r is None else _rate_cell(r) for r in found]
            n = next(r["trials"] for r in found if r is not None)
            rows.append((kind, label, str(n), *cells))
    title = f"Single-shot motion success on fresh scenes, {seed_words(seed, split and split.value)}"
    if trainings:
        title += f", each network trained {len(trainings)} times"
    title += (
        " (in brackets the 95% interval of a bootstrap that draws trainings and scenes)"
        if len(trainings or ()) > 1
        else " (in brackets the 95% interval of a bootstrap over scenes)"
    )
    title += f", in each scene of {scene}" if scene else ""
    print_table(
        marked(title, seed, split=split and split.value),
        ("primitive", "crowding", "scenes", *(LABELS[m] for m in MODELS)),
        rows,
        markdown,
    )
    trained = [
        (
            kind,
            LABELS[m],
            f"{r['parameters']:,}",
            f"{r['training_examples']:,}",
            f"{r['validation_examples']:,}",
            str(r["chosen_epoch"]),
        )
        for kind, by_model in report.items()
        for m, r in by_model.items()
        if "parameters" in r
    ]
    print_table(
        "What each network learnt from: its examples, those held out to choose its epoch",
        ("primitive", "model", "parameters", "examples", "held out", "epoch kept"),
        trained,
        markdown,
    )


@refuses_bad_input
def train_motion_search(
    config: Annotated[
        Path, typer.Option(help="The base training configuration (JSON).", parser=input_path)
    ],
    grid: Annotated[
        str,
        typer.Option(help="Settings and values, e.g. 'lr=0.001,0.0003;dropout=0,0.2'."),
    ],
    out_dir: Annotated[
        Path,
        typer.Option("--out", help="Folder of the search's trainings.", parser=out_folder),
    ],
    workers: Annotated[int, bounded_option("workers", "Trainings side by side.")] = 1,
    markdown: MarkdownFlag = False,
) -> None:
    """Every combination of a grid of training settings trained once, judged by the loss on
    its held-out training scenes (the configuration's `validation`); writes search.json and
    the chosen configuration, chosen.json, into the folder. Resumable."""
    from hsgplan.motion.search import combinations, folder_of, parse_grid, summarize
    from hsgplan.motion.train import MotionTrainConfig
    from hsgplan.trainings import train_each

    base = MotionTrainConfig.from_json(read_config(config))
    values = parse_grid(grid)
    configs = combinations(base, values)
    jobs = [(c, folder_of(out_dir, k)) for k, c in enumerate(configs)]
    train_each(_train_motion_once, jobs, workers)
    report = summarize(out_dir, configs, values)
    rows = [
        (
            str(r["combination"]),
            ", ".join(f"{k}={v}" for k, v in r["settings"].items()),
            f"{r['validation_loss']:.4f}",
            str(r["chosen_epoch"]),
            "chosen" if r["combination"] == report["chosen"] else "",
        )
        for r in report["rows"]
    ]
    print_table(
        f"{base.model} {base.primitive}: held-out training loss of each combination "
        f"({len(rows)} trainings, seed {base.seed})",
        ("combination", "settings", "held-out loss", "epoch kept", ""),
        rows,
        markdown,
    )
    if not markdown:
        out.print(f"wrote {shown(out_dir)}/search.json and chosen.json", highlight=False)
