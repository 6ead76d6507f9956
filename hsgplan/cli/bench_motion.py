"""`hsgplan bench push-reach|line-error|push-settings|compare-trials`: the measurements that
the motion primitives' constants rest on (docs/decisions.md cites each), run again after a
change to the primitives. Registered on the `bench` group in `cli/__init__.py`."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer
from rich.progress import Progress

from hsgplan.cli.common import (
    MarkdownFlag,
    SceneFiles,
    bounded_option,
    err,
    in_scene,
    input_path,
    print_table,
    refuses_bad_input,
    scene_worlds,
)

JsonFlag = Annotated[bool, typer.Option("--json", help="Print JSON.", metavar="")]
# a task index as the collections store it (int32)
MAX_TASK_INDEX = 2**31 - 1


def _cell(value, spec: str) -> str:
    return "—" if value is None else format(value, spec)


@refuses_bad_input
def push_reach(
    tasks: Annotated[
        int, bounded_option("tasks", "Push tasks, each tried as the collection tries one.")
    ] = 120,
    first: Annotated[
        int,
        typer.Option(
            help="Index of the first task in the collection's seed-0 stream (default: far "
            "past any shipped data).",
            min=0,
            max=MAX_TASK_INDEX,
            metavar="N",
        ),
    ] = 900_000,
    as_json: JsonFlag = False,
    markdown: MarkdownFlag = False,
    scene: SceneFiles = None,
) -> None:
    """PUSH_SLACK's basis: how far past the shelf's front a push's bound lies for the pushes
    that succeed, with the too-short refusal off; PUSH_SLACK must stay below the smallest."""
    from hsgplan.benchmarks.push_reach import push_reach as run

    worlds = scene_worlds(scene)
    with Progress(console=err, transient=True) as progress:
        bar = progress.add_task("push tasks", total=tasks)
        report = run(tasks, first, on_task=lambda: progress.advance(bar), worlds=worlds)
    if as_json:
        print(json.dumps(report.to_json(), indent=2))
        return
    statuses = ", ".join(f"{k} {v}" for k, v in sorted(report.statuses.items()))
    print_table(
        f"Push reach past the shelf's front, tasks {first} to {first + tasks - 1} of seed 0"
        + in_scene(scene),
        (
            "trials",
            "successes",
            "smallest margin of a success, m",
            "PUSH_SLACK, m",
            "trials under it",
            "statuses",
        ),
        [
            (
                str(report.trials),
                str(report.successes),
                _cell(report.smallest_margin_of_a_success_m, ".4f"),
                f"{report.push_slack_m:g}",
                str(report.trials_under_the_slack),
                statuses,
            )
        ],
        markdown,
    )


@refuses_bad_input
def line_error(
    tasks: Annotated[int, bounded_option("tasks", "Push tasks, run once per K.")] = 40,
    every: Annotated[
        list[int] | None,
        typer.Option(
            help="Poses (5 mm apart) per IK solve along a line; repeat for several "
            "(default: 4 and 8).",
            min=1,
            metavar="K",
        ),
    ] = None,
    as_json: JsonFlag = False,
    markdown: MarkdownFlag = False,
    scene: SceneFiles = None,
) -> None:
    """LINE_IK_EVERY's basis: how far the hand strays from a push line with the line's IK
    solved every K poses and the joints interpolated between."""
    from hsgplan.benchmarks.line_error import line_error as run

    settings = every or [4, 8]
    worlds = scene_worlds(scene)
    rows = []
    with Progress(console=err, transient=True) as progress:
        bar = progress.add_task("push tasks", total=tasks * len(settings))
        for k in settings:
            rows.append(run(tasks, k, on_task=lambda: progress.advance(bar), worlds=worlds))
    if as_json:
        print(json.dumps([r.to_json() for r in rows], indent=2))
        return
    print_table(
        f"The hand's distance from its push line, {tasks} tasks (seed 41{in_scene(scene)})",
        ("IK every", "lines", "mean mm", "p99 mm", "max mm"),
        [
            (
                str(r.every),
                str(r.lines),
                _cell(r.mean_mm, ".3f"),
                _cell(r.p99_mm, ".2f"),
                _cell(r.max_mm, ".2f"),
            )
            for r in rows
        ],
        markdown,
    )


@refuses_bad_input
def push_settings(
    scenes: Annotated[int, bounded_option("scenes", "Physics clients, one seed each.")] = 4,
    trials: Annotated[int, bounded_option("trials", "Push trials per client.")] = 192,
    setting: Annotated[
        list[str] | None,
        typer.Option(
            help="SUBSTEPS:ATTEMPTS, physics steps per 5 mm of push and pushes per staged "
            "scene; repeat for several (default: 4:4, 3:4 and 3:8).",
            metavar="S:A",
        ),
    ] = None,
    as_json: JsonFlag = False,
    markdown: MarkdownFlag = False,
    scene: SceneFiles = None,
) -> None:
    """PUSH_SUBSTEPS' and ATTEMPTS_PER_TASK's basis: push successes and CPU seconds per success
    under other push speeds and tries per staged scene."""
    from hsgplan.benchmarks.push_settings import parse_setting, tasks_per_scene
    from hsgplan.benchmarks.push_settings import push_settings as run

    chosen = [parse_setting(s) for s in setting or ["4:4", "3:4", "3:8"]]
    total = sum(scenes * tasks_per_scene(trials, s) for s in chosen)  # refuses before any work
    worlds = scene_worlds(scene)
    rows = []
    with Progress(console=err, transient=True) as progress:
        bar = progress.add_task("push tasks", total=total)
        for s in chosen:
            rows.append(
                run(scenes, trials, s, on_task=lambda: progress.advance(bar), worlds=worlds)
            )
    if as_json:
        print(json.dumps([r.to_json() for r in rows], indent=2))
        return
    print_table(
        f"Push settings: {trials} trials in each of {scenes} scenes{in_scene(scene)} (CPU time, "
        "~10% noise)",
        ("substeps", "m/s", "attempts", "trials", "successes", "CPU s per success"),
        [
            (
                str(r.substeps),
                f"{r.push_m_per_s:g}",
                str(r.attempts),
                str(r.trials),
                str(r.successes),
                f"{r.cpu_s_per_success:.3f}",
            )
            for r in rows
        ],
        markdown,
    )


TrialsPath = Annotated[
    Path,
    typer.Argument(
        help="A *_trials.npz file or a collector's work folder of chunk files.",
        parser=input_path,
        show_default=False,
    ),
]


@refuses_bad_input
def compare_trials(
    old: TrialsPath,
    new: TrialsPath,
    as_json: JsonFlag = False,
    markdown: MarkdownFlag = False,
) -> None:
    """How two collections of the same stream differ, trial by trial (after a change to the
    primitives): trials matched by task and attempt, those with other bins counted apart."""
    from hsgplan.benchmarks.compare_trials import compare_trials as run

    report = run(old, new)
    if as_json:
        print(json.dumps(report.to_json(), indent=2))
        return
    rows = [
        ("trials in both", str(report.shared)),
        ("same outcome", str(report.same_outcome)),
        ("other bins", str(report.other_bins)),
        *((change, str(n)) for change, n in report.changed.items()),
    ]
    print_table(
        "Trials of two collections, matched by task and attempt", ("", "trials"), rows, markdown
    )
