"""Learning curves of the task planner: success in the symbolic loop against the number of
demonstrations its f_preimage learned from (`hsgplan eval curve`).

Each point is a finished `eval task` run; how many demonstrations its checkpoint learned from is
read from the checkpoint itself (its training configuration's set and `demo_limit`, following a
combined checkpoint to the one its f_preimage came from), never typed by hand. The points of
every series must hold the same episodes under the same protocol (`compare.task_summaries`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from hsgplan.data.demos import load_demos
from hsgplan.domain.checks import read_json
from hsgplan.domain.errors import InvalidInputError
from hsgplan.evaluation.compare import task_summaries
from hsgplan.evaluation.table1 import PAPER_TABLE1, TextTable
from hsgplan.paths import shipped
from hsgplan.planning.regression.combine import COMBINED
from hsgplan.runner.run_folder import CONFIG
from hsgplan.training import TRAIN_CONFIG


@dataclass(frozen=True)
class CurvePoint:
    """One run of a learning curve.

    Args:
        series: the curve it belongs to.
        demonstrations: how many demonstrations its f_preimage learned from.
        success: problem size -> success rate in the symbolic loop.
        completion: problem size -> subgoal completion.
    """

    series: str
    demonstrations: int
    success: dict[int, float]
    completion: dict[int, float]


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
    held = len(load_demos(Path(config["demos"])))
    limit = config.get("demo_limit")
    return min(held, limit) if isinstance(limit, int) else held


def curve_points(series: Sequence[tuple[str, Sequence[Path]]]) -> tuple[str, list[CurvePoint]]:
    """The points of every series (name, its eval task runs), by demonstrations within a
    series, and the title line they share. Raises InvalidInputError where the runs are not like
    for like or two runs of a series learned from as many demonstrations."""
    runs = [run for _, rs in series for run in rs]
    if not runs:
        raise InvalidInputError("no run given")
    protocol, per_size, summaries = task_summaries(runs)
    points, k = [], 0
    for name, rs in series:
        seen: dict[int, Path] = {}
        for run in rs:
            checkpoint = read_json(run / CONFIG, "run configuration").get("checkpoint")
            if not isinstance(checkpoint, str):
                raise InvalidInputError(f"'{run}' names no task checkpoint")
            n = demonstrations_of(Path(checkpoint))
            if n in seen:
                raise InvalidInputError(
                    f"'{run}' and '{seen[n]}' both learned from {n} demonstrations"
                )
            seen[n] = run
            by_size = summaries[k]
            k += 1
            points.append(
                CurvePoint(
                    name,
                    n,
                    {int(s): v["success_rate"] for s, v in by_size.items()},
                    {int(s): v["subgoal_completion"] for s, v in by_size.items()},
                )
            )
    points.sort(key=lambda p: ([s for s, _ in series].index(p.series), p.demonstrations))
    title = (
        f"Success rate / subgoal completion in the symbolic loop against demonstrations "
        f"({protocol}): {per_size} goals per size"
    )
    return title, points


def curve_table(title: str, points: Sequence[CurvePoint]) -> TextTable:
    """One row per point, and the paper's Table 1 (its whole system in its world) below."""
    sizes = sorted({n for p in points for n in p.success})
    rows = [
        (p.series, str(p.demonstrations))
        + tuple(
            f"{p.success[n]:.2f} / {p.completion[n]:.2f}" if n in p.success else "—" for n in sizes
        )
        for p in points
    ]
    paper = PAPER_TABLE1["gnn"]
    rows.append(
        ("the paper's Table 1 (GNN, in its world)", "18")
        + tuple(f"{paper[n][0]:.2f} / {paper[n][1]:.2f}" if n in paper else "—" for n in sizes)
    )
    header = ("series", "demonstrations", *(f"{n} objects" for n in sizes))
    return TextTable(title, header, tuple(rows))
