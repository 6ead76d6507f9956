"""Commands on finished runs: a run's HTML report, and runs side by side."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.progress import Progress

from hsgplan.cli.common import (
    MarkdownFlag,
    bounded_option,
    err,
    input_path,
    out,
    print_table,
    refuses_bad_input,
    shown,
)
from hsgplan.cli.world import NO_RERUN, names_of
from hsgplan.domain.errors import InvalidInputError


@refuses_bad_input
def report(
    run_dir: Annotated[
        Path,
        typer.Argument(help="An eval run folder (holding summary.json).", parser=input_path),
    ],
    failures: Annotated[
        int,
        bounded_option("failures", "Failed episodes re-simulated and shown, GIF and graphs."),
    ] = 6,
    rerun: Annotated[
        bool,
        typer.Option(
            "--rerun",
            help="Also write each re-simulated episode as a rerun recording (episode.rrd). "
            "Needs the rerun extra.",
            metavar="",
        ),
    ] = False,
) -> None:
    """One self-contained HTML page for an eval run: its tables and plot, and failed episodes
    re-simulated from their seeds (a GIF with each decision, the scene graphs around the
    failing step; with --rerun, a 3D recording). Writes RUN_DIR/report.html."""
    from hsgplan.evaluation.recording import available
    from hsgplan.evaluation.report import build_report

    if rerun and not available():
        raise InvalidInputError(NO_RERUN)

    with Progress(console=err, transient=True) as progress:
        task = progress.add_task("re-simulating failed episodes", total=None)
        path = build_report(
            run_dir,
            failures,
            on_rollout=lambda r: progress.advance(task),
            on_sample=lambda n: progress.update(task, total=n),
            recordings=rerun,
        )
    size = path.stat().st_size / 1e6
    out.print(f"wrote {shown(path)} ({size:.1f} MB)", highlight=False)


@refuses_bad_input
def compare(
    runs: Annotated[
        list[Path],
        typer.Argument(
            help="Finished eval world (or eval task) run folders, one row each.",
            parser=input_path,
        ),
    ],
    names: Annotated[
        str | None,
        typer.Option(help="The rows' names, comma-separated (default: the folders' names)."),
    ] = None,
    method: Annotated[
        str | None,
        typer.Option(
            help="The column compared (gnn, mlp, ...), or one per run, comma-separated "
            "(default: the one method every run holds, else gnn)."
        ),
    ] = None,
    across_scenes: Annotated[
        bool,
        typer.Option(
            "--across-scenes",
            help="Runs of one agent in different scenes: the scene and the goals per scene file "
            "may differ, the episodes per size may not.",
        ),
    ] = False,
    across_rules: Annotated[
        bool,
        typer.Option(
            "--across-rules",
            help="Runs under different recovery rules (--rules-off): each row's rules may "
            "differ, its name says which.",
        ),
    ] = False,
    trainings: Annotated[
        int,
        typer.Option(
            help="Eval task runs: each row is this many consecutive runs, one per training of "
            "a configuration; its cells give an interval over trainings and goals.",
            min=1,
        ),
    ] = 1,
    markdown: MarkdownFlag = False,
) -> None:
    """A method's success per size across eval world runs, one row each: a ladder from one
    recipe to another, one change per row. The runs must be like for like (protocol, goals,
    repeats, seed, sizes, scene, rules off); only their checkpoints, and the method when one is
    named per run, may differ (with --across-scenes the scene, with --across-rules the rules
    off). Eval task runs (the symbolic loop) are compared the same way, on the same episodes."""
    from hsgplan.evaluation.compare import (
        all_task_runs,
        compare_task,
        compare_task_trainings,
        only_method,
    )
    from hsgplan.evaluation.compare import compare as compare_runs

    methods = [m.strip() for m in method.split(",")] if method else []
    default = methods if len(set(methods)) == len(runs) > 1 else [r.name for r in runs]
    row_names = names_of(names, "--names", "run") if names else tuple(default)
    if all_task_runs(runs):
        if across_scenes or across_rules:
            raise InvalidInputError(
                "--across-scenes and --across-rules compare eval world runs only"
            )
        if trainings > 1:
            given = names_of(names, "--names", "row") if names else None
            rows = len(runs) // trainings
            t = compare_task_trainings(
                runs, given or [f"row {k + 1}" for k in range(rows)], trainings
            )
        else:
            t = compare_task(runs, row_names)
    else:
        if trainings > 1:
            raise InvalidInputError(
                "--trainings groups eval task runs; an eval world run holds its trainings"
            )
        methods = methods or [only_method(runs)]
        t = compare_runs(runs, row_names, methods, across_scenes, across_rules)
    print_table(t.title, t.header, [list(r) for r in t.rows], markdown)
