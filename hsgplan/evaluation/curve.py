"""Learning curves (`hsgplan eval curve`): success against how much data a model learned from.

Two kinds of point, each a finished run:
- an `eval task` run: success in the symbolic loop by problem size, against the number of
  demonstrations its checkpoint's f_preimage learned from (its training configuration's set
  and `demo_limit`, following a combined checkpoint to the one its f_preimage came from);
- an `eval motion` run: single-shot success of each model of one primitive, against the
  training examples (trials) of its GNN (the checkpoint's training record).

How much data is read from the checkpoints, never typed by hand. Every point of a curve must
hold the same episodes (task) or the same scenes (motion).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from hsgplan.data.demos import load_demos
from hsgplan.domain.checks import read_json
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.scene_file import default_world
from hsgplan.evaluation.compare import over_trainings, task_summaries
from hsgplan.evaluation.motion_eval import CROWDED, LABELS, rate
from hsgplan.evaluation.table1 import PAPER_TABLE1, TextTable
from hsgplan.motion.train import SELECTION
from hsgplan.paths import shipped
from hsgplan.planning.regression.combine import COMBINED
from hsgplan.runner.run_folder import CONFIG, logged_rows
from hsgplan.training import TRAIN_CONFIG
from hsgplan.trainings import seed_folders


@dataclass(frozen=True)
class CurvePoint:
    """One run of a learning curve.

    Args:
        series: the curve it belongs to.
        amount: how much data it learned from (demonstrations, or training trials).
        success: column (a problem size, or a motion model) -> success rate.
        completion: column -> subgoal completion (task points), else None.
        interval: column -> the success rate's interval, for a point of several trainings.
    """

    series: str
    amount: int
    success: dict[str, float]
    completion: dict[str, float] | None = None
    # column -> the success rate's 95% interval over trainings and goals (or scenes), where
    # the point is of several trainings
    interval: dict[str, tuple[float, float]] = field(default_factory=dict)


@dataclass(frozen=True)
class Curves:
    """Every point, by series and amount, with what the table and the plot say of them."""

    title: str
    unit: str  # what `amount` counts
    columns: tuple[str, ...]
    points: tuple[CurvePoint, ...]
    paper: dict[str, tuple[float, float]]  # column -> the paper's success and completion


def demonstrations_of(checkpoint: Path) -> int:
    """How many demonstrations a task checkpoint's f_preimage learned from."""
    folder = shipped(checkpoint)
    if (folder / COMBINED).is_file():
        folder = shipped(Path(read_json(folder / COMBINED, "combination record")["preimage"]))
    if not (folder / TRAIN_CONFIG).is_file():
        raise InvalidInputError(f"'{folder}' holds no training configuration")
    config = read_json(folder / TRAIN_CONFIG, "training configuration")
    if not isinstance(config.get("demos"), str):
        raise InvalidInputError(f"'{folder / TRAIN_CONFIG}' names no demonstration set")
    held = len(load_demos(Path(config["demos"]), default_world()))
    limit = config.get("demo_limit")
    return min(held, limit) if isinstance(limit, int) else held


def trials_of(checkpoints: Path, primitive: str) -> int:
    """How many training examples (trials) a folder's GNN for `primitive` learned from (of a
    trainings folder, their mean over trainings: each holds out its own scenes)."""
    if trainings := seed_folders(shipped(checkpoints)):
        counts = [trials_of(folder, primitive) for folder in trainings.values()]
        return round(sum(counts) / len(counts))
    record = shipped(checkpoints) / f"{primitive}-gnn" / SELECTION
    if not record.is_file():
        raise InvalidInputError(f"'{record}' does not exist: no trained {primitive} GNN there")
    examples = read_json(record, "training record").get("training_examples")
    if not isinstance(examples, int):
        raise InvalidInputError(f"'{record}' holds no count of training examples")
    return examples


def curves(
    series: Sequence[tuple[str, Sequence[Path]]], primitive: str = "place", trainings: int = 1
) -> Curves:
    """The points of every series (its name, its runs), by amount within a series. The runs
    are all `eval task` runs or all `eval motion` runs (of `primitive`). With `trainings` K,
    each K consecutive eval task runs of a series are one point: the trainings of one
    configuration (an eval motion run holds its trainings itself). Raises InvalidInputError
    where they are not like for like, or where two points of a series learned from as much
    data."""
    runs = [run for _, rs in series for run in rs]
    if not runs:
        raise InvalidInputError("no run given")
    kinds = {read_json(run / CONFIG, "run configuration").get("kind") for run in runs}
    if trainings < 1 or any(len(rs) % trainings for _, rs in series):
        raise InvalidInputError(
            f"--trainings {trainings}: give each point of a series all its {trainings} runs"
        )
    groups = [
        tuple(rs[k : k + trainings]) for _, rs in series for k in range(0, len(rs), trainings)
    ]
    if kinds == {"eval-motion"}:
        if trainings != 1:
            raise InvalidInputError("an eval motion run holds its trainings: --trainings 1")
        made = _motion(runs, primitive)
    elif kinds == {"eval-task"}:
        made = _task(runs, groups)
    else:
        raise InvalidInputError("a curve's runs are all eval task runs or all eval motion runs")
    title, unit, columns, by_point, paper = made
    points = []
    for name, rs in series:
        seen: dict[int, Path] = {}
        for k in range(0, len(rs), trainings):
            group = tuple(rs[k : k + trainings])
            amount, success, completion, interval = by_point[group if trainings > 1 else group[0]]
            if amount in seen:
                raise InvalidInputError(
                    f"'{group[0]}' and '{seen[amount]}' both learned from {amount}"
                )
            seen[amount] = group[0]
            points.append(CurvePoint(name, amount, success, completion, interval))
    order = [name for name, _ in series]
    points.sort(key=lambda p: (order.index(p.series), p.amount))
    return Curves(title, unit, columns, tuple(points), paper)


def _task(runs: Sequence[Path], groups: Sequence[tuple[Path, ...]]):
    protocol, per_size, summaries = task_summaries(runs)
    by_run = {}
    for run, by_size in zip(runs, summaries, strict=True):
        checkpoint = read_json(run / CONFIG, "run configuration").get("checkpoint")
        if not isinstance(checkpoint, str):
            raise InvalidInputError(f"'{run}' names no task checkpoint")
        by_run[run] = (
            demonstrations_of(Path(checkpoint)),
            {f"{n} objects": v["success_rate"] for n, v in by_size.items()},
            {f"{n} objects": v["subgoal_completion"] for n, v in by_size.items()},
            {},
        )
    sizes = sorted({int(n) for s in summaries for n in s})
    for group in (g for g in groups if len(g) > 1):  # a point of several trainings
        amounts = {by_run[run][0] for run in group}
        if len(amounts) > 1:
            raise InvalidInputError(
                f"the runs from '{group[0]}' on learned from {sorted(amounts)}: one point's "
                "trainings learn from as much data"
            )
        cells = dict(
            zip((f"{n} objects" for n in sizes), over_trainings(group, sizes), strict=True)
        )
        by_run[group] = (
            amounts.pop(),
            {col: mean for col, (mean, _, _) in cells.items()},
            {col: done for col, (_, _, done) in cells.items()},
            {col: ci for col, (_, ci, _) in cells.items()},
        )
    columns = tuple(f"{n} objects" for n in sizes)
    paper = {f"{n} objects": rates for n, rates in PAPER_TABLE1["gnn"].items()}
    title = (
        f"Success rate / subgoal completion in the symbolic loop against demonstrations "
        f"({protocol}): {per_size} goals per size"
    )
    return title, "demonstrations", columns, by_run, paper


def _motion(runs: Sequence[Path], primitive: str):
    by_run: dict[Path, tuple] = {}
    scenes: tuple = ()
    for run in runs:
        config = read_json(run / CONFIG, "run configuration")
        rows = [
            r
            for row in logged_rows(run)
            if str(row.get("key", "")).startswith(f"{primitive}/")
            for r in row["result"]
        ]
        if not rows:
            raise InvalidInputError(f"'{run}' holds no finished {primitive} scene")
        tasks = (config.get("seed"), frozenset(r["task"] for r in rows))
        if not scenes:
            scenes = tasks
        elif tasks != scenes:
            raise InvalidInputError(
                f"'{run}' and '{runs[0]}' differ in seed or scenes: a curve's points must be "
                "like for like"
            )
        success = {}
        for model in ("gnn", "random"):  # the curve's model and the floor
            mine = [r for r in rows if r["model"] == model]
            if mine:
                success[LABELS[model]] = sum(r["ok"] for r in mine) / len(mine)
            crowded = [r["ok"] for r in mine if r["shelf_top"] and r["crowding"] >= CROWDED]
            if crowded:  # where a place is hardest: a shelf top half full or more
                success[f"{LABELS[model]}, crowded shelf tops"] = sum(crowded) / len(crowded)
        if not isinstance(checkpoints := config.get("checkpoints"), str):
            raise InvalidInputError(f"'{run}' names no motion checkpoints")
        interval = {}
        if len({r.get("training") for r in rows}) > 1:  # the trainings of a trainings folder
            for model in ("gnn", "random"):
                mine = [r for r in rows if r["model"] == model]
                if mine and (ci := rate(mine).get("success_ci")):
                    interval[LABELS[model]] = tuple(ci)
        by_run[run] = (trials_of(Path(checkpoints), primitive), success, None, interval)
    title = (
        f"Single-shot {primitive} success on fresh scenes against the GNN's training trials: "
        f"{len(scenes[1])} scenes, seed {scenes[0]}"
    )
    columns = tuple(dict.fromkeys(col for _, success, *_ in by_run.values() for col in success))
    return title, "training trials", columns, by_run, {}


def curve_table(c: Curves) -> TextTable:
    """One row per point, and for task curves the paper's Table 1 (its system, its world)."""

    def cell(p: CurvePoint, col: str) -> str:
        if col not in p.success:
            return "—"
        digits = 3 if p.completion is None else 2
        rate = f"{p.success[col]:.{digits}f}"
        if col in p.interval:
            low, high = p.interval[col]
            rate += f" ({low:.{digits}f}–{high:.{digits}f})"
        return rate if p.completion is None else f"{rate} / {p.completion[col]:.2f}"

    rows = [(p.series, f"{p.amount:,}", *(cell(p, col) for col in c.columns)) for p in c.points]
    if c.paper:
        rows.append(
            ("the paper's Table 1 (GNN, in its world)", "18")
            + tuple(
                f"{c.paper[col][0]:.2f} / {c.paper[col][1]:.2f}" if col in c.paper else "—"
                for col in c.columns
            )
        )
    return TextTable(c.title, ("series", c.unit, *c.columns), tuple(rows))
