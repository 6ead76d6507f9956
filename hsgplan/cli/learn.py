"""Commands of the learned task planner: `train task`, `eval task`, `eval reach`."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer
from rich.progress import Progress

from hsgplan.cli.common import (
    CollectWorkers,
    MarkdownFlag,
    ProtocolName,
    RayAddress,
    RunFolder,
    SceneFiles,
    Summaries,
    SymbolicPlannerName,
    TaskCheckpoint,
    bounded_option,
    check_ray,
    dash,
    default_networks,
    err,
    input_path,
    out,
    out_file,
    out_folder,
    parse_sizes,
    print_table,
    read_config,
    refuses_bad_input,
    scene_worlds,
    shown,
)
from hsgplan.cli.seeding import SeedOrSplitStart, SplitOption, TrainingSeeds, split_seed
from hsgplan.domain.checks import resolve
from hsgplan.evaluation.seeds import marked, seed_words
from hsgplan.paths import REACH_HELD_OUT, RUNS, TASK_CHECKPOINT

train_app = typer.Typer(
    cls=Summaries, no_args_is_help=True, help="Train the learned models (resumable)."
)
REGRESSION = SymbolicPlannerName("regression")


@train_app.command("task")
@refuses_bad_input
def train_task(
    config: Annotated[
        Path | None, typer.Option(help="Training configuration (JSON).", parser=input_path)
    ] = None,
    out_dir: Annotated[
        Path,
        typer.Option(
            "--out",
            help="Checkpoint folder (default: runs/train-task; a shipped checkpoint is never "
            "written unless named).",
            parser=out_folder,
        ),
    ] = RUNS / "train-task",
    seed: Annotated[
        int | None,
        bounded_option("seed", "Overrides the configuration's seed."),
    ] = None,
    seeds: TrainingSeeds = None,
    workers: Annotated[
        int, bounded_option("workers", "With --seeds, the trainings' networks train side by side.")
    ] = 1,
) -> None:
    """Train f_preimage, f_reach and the forward baseline on the demonstrations."""
    from dataclasses import replace

    from hsgplan.planning.regression.train import TaskTrainConfig
    from hsgplan.trainings import record, seed_folder, train_each, training_seeds

    settings = read_config(config)
    if seed is not None:
        settings["seed"] = seed
    cfg = TaskTrainConfig.from_json(settings)
    if seeds is None:
        _train_task_once(cfg, out_dir)
        out.print(f"trained f_preimage, f_reach and the forward baseline into {shown(out_dir)}")
        return
    every = training_seeds(cfg.seed, seeds)
    jobs = [(replace(cfg, seed=s), seed_folder(out_dir, s)) for s in every]
    if workers > 1:
        _train_networks_apart(jobs, workers)
    else:
        train_each(_train_task_once, jobs, workers)
    record(out_dir, every, "task")
    for _, folder in jobs:
        out.print(f"trained f_preimage, f_reach and the forward baseline into {shown(folder)}")


# the networks of a training, the longest to train first (f_reach: measured 36 against 19 and
# 3 minutes in the paper's recipe), so that the last to start are the shortest
NETWORK_ORDER = ("reach", "preimage", "forward")


def _train_networks_apart(jobs: list, workers: int) -> None:
    """Each network of each training a job of its own, `workers` at a time: three trainings
    on two workers no longer leave one core idle while the third trains alone. Every folder
    is claimed first, so a bad configuration is refused before anything trains."""
    from hsgplan.domain.kitchen import KITCHEN
    from hsgplan.planning.regression.train import claim_task
    from hsgplan.runner.lock import release
    from hsgplan.trainings import train_each

    for cfg, folder in jobs:
        claim_task(cfg, folder, KITCHEN)
    apart = [((cfg, name), folder) for name in NETWORK_ORDER for cfg, folder in jobs]
    try:
        train_each(_train_task_network, apart, workers)
    finally:  # the folders are let go with the trainings, finished or not
        for _, folder in jobs:
            release(folder)


def _train_task_network(job: tuple, folder: Path, show: bool = False) -> None:
    from hsgplan.domain.kitchen import KITCHEN
    from hsgplan.planning.regression.train import train_task as run

    cfg, name = job
    run(cfg, folder, None, world=KITCHEN, networks=(name,), claimed=True)


def _train_task_once(cfg, folder: Path, show: bool = True) -> None:
    from hsgplan.domain.kitchen import KITCHEN
    from hsgplan.planning.regression.train import train_task as run

    if not show:
        run(cfg, folder, None, world=KITCHEN)
        return
    with Progress(console=err, transient=True) as progress:
        bars = {}

        def on_epoch(name: str, epoch: int, loss: float) -> None:
            if name not in bars:
                bars[name] = progress.add_task(name, total=cfg.epochs)
            progress.update(bars[name], completed=epoch, description=f"{name} loss {loss:.4f}")

        run(cfg, folder, on_epoch, world=KITCHEN)  # of data recorded without a scene file


@train_app.command("combine")
@refuses_bad_input
def combine_task(
    preimage: Annotated[
        Path,
        typer.Option(
            help="Task checkpoint whose f_preimage (and forward) is taken.", parser=input_path
        ),
    ],
    reach: Annotated[
        Path, typer.Option(help="Task checkpoint whose f_reach is taken.", parser=input_path)
    ],
    out_dir: Annotated[
        Path, typer.Option("--out", help="Checkpoint folder to write.", parser=out_folder)
    ],
) -> None:
    """A task checkpoint of one checkpoint's f_preimage and another's f_reach, copied, nothing
    trained (the f_preimage x f_reach grid); combined.json names the sources."""
    from hsgplan.planning.regression.combine import combine

    combine(preimage, reach, out_dir)
    out.print(f"f_preimage of {shown(preimage)}, f_reach of {shown(reach)}: {shown(out_dir)}")


RECOVERING_PROTOCOL = ProtocolName("recovering")


@refuses_bad_input
def eval_task(
    planner: Annotated[SymbolicPlannerName, typer.Option(help="Task planner.")] = REGRESSION,
    sizes: Annotated[str, typer.Option(help="Problem sizes, e.g. 2-12.")] = "2-12",
    goals: Annotated[int, bounded_option("goals", "Random goals per size.")] = 100,
    seed: SeedOrSplitStart = None,
    split: SplitOption = None,
    goals_file: Annotated[
        Path | None, typer.Option(help="Goals from a file instead.", parser=input_path)
    ] = None,
    checkpoint: TaskCheckpoint = None,
    workers: CollectWorkers = 2,
    ray: RayAddress = None,
    run_dir: RunFolder = None,
    protocol: Annotated[
        ProtocolName,
        typer.Option(
            help="paper: the first inapplicable action ends the episode and the planner has no "
            "recovery rule; recovering: it costs its step.",
            metavar="PROTOCOL",
        ),
    ] = RECOVERING_PROTOCOL,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print one JSON object.", metavar="")
    ] = False,
    markdown: MarkdownFlag = False,
    scene: SceneFiles = None,
) -> None:
    """A task planner in the symbolic closed loop: success, plan length against Fast Downward,
    wasted (inapplicable) actions per episode, milliseconds per decision. Episodes are kept in
    the run folder (by default
    runs/eval-task-PLANNER[-CHECKPOINT]-SIZES-gGOALS-seedSEED[-paper][-SCENE]) as they
    finish."""
    from hsgplan.evaluation.task_eval import evaluate_task, summarize_task

    planner = planner.value
    given, _ = default_networks(f"{planner}+sampler", scene_worlds(scene), checkpoint, None)
    checkpoint = given or TASK_CHECKPOINT
    seed = split_seed(seed, split)
    split_name = split and split.value
    size_list = parse_sizes(sizes)
    total = goals * len(size_list) if goals_file is None else None
    source = goals_file.stem if goals_file else f"g{goals}"
    tag = "" if checkpoint == TASK_CHECKPOINT else f"-{resolve(checkpoint).name}"
    paper = "-paper" if protocol.value == "paper" else ""
    where = f"-{scene.stem}" if scene else ""
    run_dir = run_dir or RUNS / (
        f"eval-task-{planner}{tag}-{sizes}-{source}-{split_name or f'seed{seed}'}{paper}{where}"
    )
    check_ray(ray)
    with Progress(console=err, transient=True) as progress:
        task = progress.add_task(f"{planner} episodes", total=total)
        episodes = evaluate_task(
            planner,
            checkpoint,
            size_list,
            goals,
            seed,
            goals_file,
            workers,
            lambda e: progress.advance(task),
            run_dir,
            ray,
            protocol.value,
            scene,
            split_name,
        )
    report = summarize_task(episodes) | {
        "planner": planner,
        "seed": seed,
        "split": split_name,
        "protocol": protocol.value,
        **({"scene": str(scene)} if scene else {}),
    }
    if as_json:
        print(json.dumps(report, indent=2))
        return

    rows = [
        (
            n,
            dash(v["success_rate"], ".3f"),
            dash(v["plan_length_ratio"], ".3f"),
            dash(v["wasted_per_episode"], ".2f"),
            dash(v["ms_per_decision"], ".1f"),
            str(v["episodes"]),
            ", ".join(f"{k} {c}" for k, c in sorted(v["failures"].items())) or "—",
        )
        for n, v in report["by_size"].items()
    ]
    print_table(
        marked(
            f"{planner} in the symbolic loop, {goals} goals per size, "
            f"{seed_words(seed, split_name)}"
            + (" (paper protocol)" if paper else "")
            + (f", {_scenes_shown(scene)}" if scene else ""),
            seed,
            split=split_name,
        ),
        (
            "objects",
            "success",
            "plan length / FD",
            "wasted actions",
            "ms per decision",
            "episodes",
            "failures",
        ),
        rows,
        markdown,
    )


def _worlds(report: dict) -> int:
    """How many worlds other than the kitchen an `eval reach` report's trials were staged in."""
    return len(report.get("worlds") or ())


@refuses_bad_input
def eval_reach(
    checkpoint: Annotated[
        Path, typer.Option(help="Task planner checkpoint.", parser=input_path)
    ] = TASK_CHECKPOINT,
    data: Annotated[
        Path,
        typer.Option(
            help="Held-out executed primitives (`hsgplan collect reach`).", parser=input_path
        ),
    ] = REACH_HELD_OUT,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print one JSON object.", metavar="")
    ] = False,
    markdown: MarkdownFlag = False,
) -> None:
    """f_reach against the simulated world: precision and recall of "reachable" on held-out
    executed primitives, by the situation that decides them (hand full, surface full, ...)."""
    from hsgplan.evaluation.reach_eval import evaluate_reach
    from hsgplan.paths import shipped

    report = evaluate_reach(shipped(checkpoint), shipped(data))
    if as_json:
        print(json.dumps(report, indent=2))
        return

    def dash(v):
        return "—" if v is None else f"{v:.3f}"

    rows = [
        (
            kind,
            str(v["questions"]),
            str(v["reachable"]),
            dash(v["precision"]),
            dash(v["recall"]),
            dash(v["false_yes_rate"]),
            dash(v["accuracy"]),
        )
        for kind, v in [*report["by_kind"].items(), ("all", report["overall"])]
    ]
    print_table(
        f"f_reach of {checkpoint} on {report['trials']} executed primitives from {data}"
        + (f" (staged in {n} worlds)" if (n := _worlds(report)) else ""),
        ("question", "n", "reachable", "precision", "recall", "yes when not", "accuracy"),
        rows,
        markdown,
    )


@refuses_bad_input
def eval_curve(
    series: Annotated[
        list[str],
        typer.Option(
            "--series",
            help="NAME=RUN,RUN,...: one curve, its points finished eval task runs (or eval "
            "motion runs) of models that learned from different amounts of data (repeat for "
            "more curves).",
        ),
    ],
    primitive: Annotated[
        str, typer.Option(help="The primitive of eval motion runs: place or push.")
    ] = "place",
    plot: Annotated[
        Path | None,
        typer.Option(help="Also draw the curves into this PNG.", parser=out_file),
    ] = None,
    trainings: Annotated[
        int,
        typer.Option(
            help="Eval task runs: each point is this many consecutive runs of a series, one "
            "per training of a configuration; its cells give an interval over trainings and "
            "goals.",
            min=1,
        ),
    ] = 1,
    markdown: MarkdownFlag = False,
) -> None:
    """Learning curves: success against how much data a model learned from, read from each
    run's checkpoint. Eval task runs: success in the symbolic loop by size against the
    demonstrations of f_preimage, beside the paper's Table 1. Eval motion runs: single-shot
    success of the GNN (and Random) against the GNN's training trials. The points must be
    like for like (the same episodes, or the same scenes)."""
    from hsgplan.domain.errors import InvalidInputError
    from hsgplan.evaluation.curve import curve_table, curves

    if primitive not in ("place", "push"):
        raise InvalidInputError(f"--primitive {primitive!r}: place or push")
    parsed = []
    for text in series:
        name, sep, runs = text.partition("=")
        folders = [r.strip() for r in runs.split(",") if r.strip()]
        if not sep or not name.strip() or not folders:
            raise InvalidInputError(f"--series {text!r}: write NAME=RUN,RUN,...")
        parsed.append((name.strip(), [Path(r) for r in folders]))
    if len({name for name, _ in parsed}) < len(parsed):
        raise InvalidInputError("two --series share a name")
    c = curves(parsed, primitive, trainings)
    table = curve_table(c)
    print_table(table.title, table.header, [list(r) for r in table.rows], markdown)
    if plot is not None:
        from hsgplan.viz.plots import plot_learning_curves

        drawn: dict[str, dict[int, dict[str, float]]] = {name: {} for name, _ in parsed}
        for p in c.points:
            drawn[p.series][p.amount] = p.success
        spread: dict[str, dict[int, dict[str, tuple[float, float]]]] = {n: {} for n in drawn}
        for p in c.points:
            spread[p.series][p.amount] = p.interval
        paper = {col: rates[0] for col, rates in c.paper.items()}
        plot_learning_curves(drawn, paper, c.unit, plot, spread)
        err.print(f"wrote {shown(plot)}", highlight=False)  # stdout stays the table alone


def _scenes_shown(scene: Path) -> str:
    if scene.is_dir():
        return f"each of the {len(list(scene.glob('*.toml')))} scenes in {scene}"
    return f"scene {scene}"


@refuses_bad_input
def labels(
    checkpoints: Annotated[
        list[Path] | None,
        typer.Argument(
            help="Task checkpoints or motion networks' folders (default: the shipped agent's).",
            parser=input_path,
            show_default=False,
        ),
    ] = None,
    markdown: MarkdownFlag = False,
) -> None:
    """Where every training label of the networks comes from and who labelled it: each
    source's examples and labels (by class), the hand-written rules among them named."""
    from hsgplan.evaluation.labels import label_rows
    from hsgplan.paths import MOTION_CHECKPOINTS, TASK_CHECKPOINT

    shipped = [TASK_CHECKPOINT, *(MOTION_CHECKPOINTS / n for n in ("place-gnn", "push-gnn"))]
    rows = [r for c in checkpoints or shipped for r in label_rows(c)]
    print_table(
        "Where the networks' training labels come from (counts of the trained checkpoints)",
        ("network", "source", "examples", "labels", "by class", "labelled by"),
        [(r.network, r.source, str(r.examples), str(r.labels), r.by_class, r.who) for r in rows],
        markdown,
    )
