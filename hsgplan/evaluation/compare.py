"""Finished `eval world` runs side by side, one row each: a ladder from one recipe to another,
one change per row.

The runs must be like for like (protocol, goals, repeats, seed, sizes, rules switched off):
only what the agent reads (its checkpoints) may differ, so a row's gain over the row above is
the change that row names.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from hsgplan.domain.checks import read_json
from hsgplan.domain.errors import InvalidInputError
from hsgplan.evaluation.report import read_summary
from hsgplan.evaluation.seeds import marked
from hsgplan.evaluation.table1 import PAPER_TABLE1, TextTable, cell, label, protocol_name
from hsgplan.runner.run_folder import CONFIG

# what rows must share; the checkpoints are what a ladder's rows change
LIKE_FOR_LIKE = ("protocol", "rules_off", "goals", "goals_file", "repeats", "seed", "sizes")


def compare(runs: Sequence[Path], names: Sequence[str], method: str) -> TextTable:
    """One row per run folder (`names[i]` for `runs[i]`): `method`'s success rate and subgoal
    completion per size, and the paper's row where it reports `method`.

    Raises InvalidInputError for a folder that is no finished eval world run, one without
    `method`, or runs that are not like for like (the first setting that differs is named)."""
    if len(names) != len(runs):
        raise InvalidInputError(f"{len(runs)} runs and {len(names)} names: name each run once")
    summaries = [read_summary(run) for run in runs]
    settings = [_settings(run) for run in runs]
    for run, summary, s in zip(runs, summaries, settings, strict=True):
        if method not in summary["methods"]:
            known = ", ".join(summary["methods"])
            raise InvalidInputError(f"'{run}' holds no method '{method}' (it holds {known})")
        for key in LIKE_FOR_LIKE:
            if s.get(key) != settings[0].get(key):
                raise InvalidInputError(
                    f"'{run}' and '{runs[0]}' differ in {key} ({s.get(key)} against "
                    f"{settings[0].get(key)}): a comparison's rows must be like for like"
                )
    sizes = sorted({int(n) for s in summaries for n in s["methods"][method]["by_size"]})
    rows = []
    for name, summary in zip(names, summaries, strict=True):
        by_size = summary["methods"][method]["by_size"]
        rows.append((name, *(cell(by_size[str(n)]) if str(n) in by_size else "—" for n in sizes)))
    if paper := PAPER_TABLE1.get(method):
        cells = (f"{paper[n][0]:.2f} / {paper[n][1]:.2f}" if n in paper else "—" for n in sizes)
        rows.append((f"{label(method)} (paper)", *cells))
    first = summaries[0]
    source = first["goals_file"] or f"{first['goals']} random goals per size"
    repeats = "each run once" if first["repeats"] == 1 else f"each run {first['repeats']} times"
    title = (
        f"Success rate / subgoal completion of {label(method)} by run ({protocol_name(first)}): "
        f"{source}, {repeats}, seed {first['seed']}"
    )
    header = ("run", *(f"{n} objects" for n in sizes))
    return TextTable(marked(title, first["seed"]), header, tuple(rows))


def _settings(run: Path) -> dict:
    return read_json(run / CONFIG, "run configuration")
