"""`hsgplan splits show|check`: the declared splits, and whether the test split is sealed."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from hsgplan.cli.common import (
    Summaries,
    input_path,
    out,
    parse_sizes,
    print_table,
    refuses_bad_input,
)

app = typer.Typer(
    cls=Summaries,
    no_args_is_help=True,
    help="The train, tune and test splits, and whether the test split is sealed (docs/splits.md).",
)
Markdown = Annotated[bool, typer.Option("--markdown", help="Print Markdown.", metavar="")]


def _span(r: range) -> str:
    return f"{r.start}..{r.stop - 1}"


@app.command()
@refuses_bad_input
def show(
    markdown: Markdown = False,
) -> None:
    """Each split's run seeds, share of the goal space and layout seeds."""
    from hsgplan.evaluation.splits import BUCKETS, SHARED_SIZES, SPLITS

    rows = [
        (
            s.name,
            _span(s.seeds),
            f"{len(s.goal_share)} of {BUCKETS} buckets ({_span(s.goal_share)})",
            _span(s.layouts),
        )
        for s in SPLITS.values()
    ]
    shared = ", ".join(map(str, sorted(SHARED_SIZES)))
    title = f"The splits (goal spaces of {shared} objects are shared by all)"
    print_table(title, ("split", "run seeds", "goals", "layout seeds"), rows, markdown)


@app.command()
@refuses_bad_input
def check(
    roots: Annotated[
        list[Path] | None,
        typer.Argument(help="Folders to search for collections and runs (default: data runs)."),
    ] = None,
    sizes: Annotated[str, typer.Option(help="The test split's sizes.")] = "2-6,8,10,12",
    markdown: Markdown = False,
) -> None:
    """Exit 1 where the test split shares a (goal, start scene) with a collection or a tuning
    run, or a goal where its size's goal space is cut; say what each size shares."""
    from hsgplan.evaluation.split_check import check as run_check

    folders = roots or [p for p in (Path("data"), Path("runs")) if p.exists()]
    reports, found = run_check(folders, parse_sizes(sizes))
    read = ", ".join(f"{n} {kind}" for kind, n in sorted(found.folders.items())) or "nothing"
    rows = [
        (
            str(r.size),
            str(r.space) if r.space is not None else "cut",
            str(len(r.test_goals)),
            str(len(r.shared_training)),
            str(len(r.shared_tuning)),
            str(len(r.shared_pairs)),
            "sealed" if r.sealed else "LEAKS",
        )
        for r in reports
    ]
    header = ("objects", "goal space", "test goals", "in training", "in tuning", "pairs", "")
    title = f"The test split against {read} under {', '.join(map(str, folders))}"
    print_table(title, header, rows, markdown)
    leaks = [r for r in reports if not r.sealed]
    for r in leaks:
        for d, other in r.shared_pairs[:3]:
            out.print(f"{r.size} objects: ({d.goal}, seed {d.seed}) also in {other.source}")
        if r.shared_training or r.shared_tuning:
            goal = sorted(r.shared_training | r.shared_tuning)[0]
            out.print(f"{r.size} objects: goal {goal} is drawn by training or tuning too")
    for line in found.leaks():
        out.print(line, highlight=False)
    if leaks or found.leaks():
        raise typer.Exit(1)
    out.print("the test split is sealed", highlight=False)


@app.command()
@refuses_bad_input
def decisions(
    record: Annotated[Path, typer.Option(help="The record of choices.", parser=input_path)] = Path(
        "configs/decisions.toml"
    ),
    markdown: Markdown = False,
) -> None:
    """Every recorded choice, the split and seeds it was made on and where it stands; exit 1
    where a row cites a test seed or calls a seed a tuning seed that is none."""
    from hsgplan.evaluation import decisions as record_of
    from hsgplan.evaluation.split_check import drawn_by_test

    rows = record_of.read_decisions(record)
    episodes = frozenset(d.seed for d in drawn_by_test())
    opened = sum(d.open for d in rows)
    title = (
        f"{len(rows)} recorded choices; {opened} made on a reporting seed are still to be "
        "made again on the tune split"
    )
    if markdown:
        print(f"{title} (each: what, the split it was chosen on and its seeds, by what)\n")
        print(record_of.markdown(rows) + "\n")
    else:
        print_table(title, record_of.HEADER, record_of.rows(rows), markdown)
    bad = [
        f"{d.name} cites test seed(s) {', '.join(map(str, cited))}"
        for d in rows
        if (cited := record_of.cited_test_seeds(d, episodes))
    ] + [
        f"{d.name} is said chosen on tune, but {', '.join(map(str, seeds))} is no tuning seed"
        for d in rows
        if (seeds := record_of.misfiled(d))
    ]
    for line in bad:
        out.print(line, highlight=False)
    if bad:
        raise typer.Exit(1)
