"""The `hsgplan` command. It parses, calls the package and prints; nothing else lives here."""

from __future__ import annotations

import functools
import json
import sys
from enum import StrEnum
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.progress import Progress
from rich.table import Table

from hsgplan.domain.errors import InvalidInputError

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="Hierarchical planning with geometric and symbolic scene graphs (kitchen storage).",
)
bench_app = typer.Typer(no_args_is_help=True, help="Measure speed (medians over one run).")
app.add_typer(bench_app, name="bench")
out = Console()
err = Console(stderr=True)


def refuses_bad_input(fn):
    """Bad input becomes one line on stderr and exit code 2, never a traceback."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        try:
            return fn(*args, **kwargs)
        except InvalidInputError as e:
            err.print(f"[bold red]error:[/] {e}", highlight=False, markup=True, soft_wrap=True)
            raise typer.Exit(2) from None
        except KeyboardInterrupt:
            err.print("interrupted")
            raise typer.Exit(130) from None

    return wrapper


class Search(StrEnum):
    auto = "auto"
    optimal = "optimal"
    fast = "fast"

    @property
    def optimal_flag(self) -> bool | None:
        return {"auto": None, "optimal": True, "fast": False}[self.value]


def parse_sizes(text: str) -> list[int]:
    """`2-6`, `2,4,6` or `3` as a list of sizes."""
    sizes: list[int] = []
    try:
        for part in text.split(","):
            lo, _, hi = part.strip().partition("-")
            sizes += list(range(int(lo), int(hi or lo) + 1))
    except ValueError:
        raise InvalidInputError(
            f"--sizes '{text}': expected a range like 2-6 or a list like 2,4,6"
        ) from None
    from hsgplan.domain.generator import check_size

    if not sizes:
        raise InvalidInputError(f"--sizes '{text}' names no size")
    for n in sizes:
        check_size(n)
    return sizes


def _scene(goal_text: str, objects: str | None, init: str | None):
    from hsgplan.domain.goals import parse_goal
    from hsgplan.domain.objects import kind_of, sort_objects
    from hsgplan.scene_graph.symbolic import SymbolicSceneGraph

    goal = parse_goal(goal_text)
    names = list(goal.objects)
    if objects:
        given = [o.strip() for o in objects.split(",") if o.strip()]
        for o in given:
            kind_of(o)
        missing = [o for o in goal.objects if o not in given]
        if missing:
            raise InvalidInputError(f"--objects lacks '{missing[0]}', which the goal names")
        names = list(sort_objects(given))
    if init:
        literals = parse_goal(init, validate=False).literals
        extra = {o for lit in literals for o in lit.objects()} - set(names)
        if extra:
            raise InvalidInputError(f"--init names '{sorted(extra)[0]}', which is not in the scene")
        state = SymbolicSceneGraph.from_literals(names, literals)
    else:
        state = SymbolicSceneGraph.initial(names)
    return goal, state


def _print_plan(plan, goal) -> None:
    out.print(f"[bold]goal[/] ({goal.size} objects): {goal}", highlight=False)
    for i, state in enumerate(plan.states):
        head = "start" if i == 0 else f"step {i}: [bold cyan]{plan.actions[i - 1]}[/]"
        out.print(f"\n{head}", highlight=False)
        out.print(state.to_text(), highlight=False, markup=False)
    out.print(
        f"\n{len(plan)} actions, planned by {plan.planner} in {plan.seconds:.2f} s; "
        f"goal holds: {goal.satisfied_by(plan.states[-1])}",
        highlight=False,
    )


@app.command()
@refuses_bad_input
def plan(
    goal: Annotated[
        str, typer.Option(help="Goal literals, e.g. 'On(butter, shelf_a) & In(cherries, shelf_a)'.")
    ],
    objects: Annotated[
        str | None,
        typer.Option(help="Comma-separated objects in the scene (default: those the goal names)."),
    ] = None,
    init: Annotated[
        str | None,
        typer.Option(help="Start state as On/In/InGrasp literals (default: all on open_space)."),
    ] = None,
    search: Annotated[
        Search,
        typer.Option(
            help="optimal: shortest plan (A* with LM-cut, slow past 8 objects); "
            "fast: weighted A*; auto: optimal up to 6 objects."
        ),
    ] = Search.auto,
    as_json: Annotated[bool, typer.Option("--json", help="Print the plan as JSON.")] = False,
) -> None:
    """Plan a goal with Fast Downward and show the symbolic state after each step."""
    from hsgplan.planning.fast_downward import FastDownwardPlanner

    g, state = _scene(goal, objects, init)
    result = FastDownwardPlanner(optimal=search.optimal_flag).plan(state, g)
    if as_json:
        steps = [
            {
                "step": i,
                "action": None if i == 0 else str(result.actions[i - 1]),
                "state": [str(lit) for lit in s.sorted_literals()],
            }
            for i, s in enumerate(result.states)
        ]
        print(json.dumps(steps, indent=2))
    else:
        _print_plan(result, g)


@app.command()
@refuses_bad_input
def goals(
    objects: Annotated[int, typer.Option(help="Objects per goal (2-12).")],
    count: Annotated[int, typer.Option(help="How many goals.")],
    seed: Annotated[int, typer.Option(help="Random seed; the same seed gives the same goals.")] = 0,
    out_file: Annotated[
        Path | None, typer.Option("--out", help="Goal file to write (default: stdout).")
    ] = None,
    stacking: Annotated[bool, typer.Option(help="Allow stacked goals.")] = True,
) -> None:
    """Write random feasible goals, one per line (the distribution is in `domain/generator.py`)."""
    from hsgplan.domain.generator import check_size, random_goals
    from hsgplan.domain.goals import write_goal_file

    check_size(objects)
    drawn = random_goals(objects, count, seed, stacking=stacking)
    header = f"hsgplan goals --objects {objects} --count {count} --seed {seed}" + (
        "" if stacking else " --no-stacking"
    )
    if out_file is None:
        print(f"# {header}")
        for g in drawn:
            print(g)
        return
    if out_file.exists() and out_file.is_dir():
        raise InvalidInputError(f"--out '{out_file}' is a directory")
    write_goal_file(out_file, drawn, header=header)
    err.print(f"wrote {len(drawn)} goals to {out_file}")


@app.command()
@refuses_bad_input
def demo(
    agent: Annotated[str, typer.Option(help="Which agent acts.")] = "oracle",
    goal: Annotated[
        str | None, typer.Option(help="Goal literals (default: a random goal).")
    ] = None,
    objects: Annotated[int, typer.Option(help="Objects in the random goal (2-12).")] = 4,
    seed: Annotated[int, typer.Option(help="Seed for the goal and the scene.")] = 0,
    out_dir: Annotated[Path, typer.Option("--out", help="Folder for the pictures.")] = Path(
        "runs/demo"
    ),
) -> None:
    """One episode in the simulated kitchen: a GIF, a scene-graph drawing per step, a record."""
    from hsgplan.domain.generator import check_size
    from hsgplan.domain.goals import parse_goal
    from hsgplan.evaluation.demo import demo_goal, run_demo
    from hsgplan.evaluation.protocol import make_agent

    make_agent(agent)
    if goal is None:
        check_size(objects)
    g = parse_goal(goal) if goal else demo_goal(objects, seed)
    if out_dir.exists() and not out_dir.is_dir():
        raise InvalidInputError(f"--out '{out_dir}' is a file")
    out.print(f"[bold]goal[/] ({g.size} objects, seed {seed}): {g}", highlight=False)
    with err.status("running the episode"):
        record = run_demo(agent, g, seed, out_dir)
    for s in record.steps:
        out.print(f"{s.step:>2}  {s.params:<55} {s.status}", highlight=False, markup=False)
    verdict = "[green]success[/]" if record.success else f"[red]failed: {record.failure}[/]"
    out.print(
        f"{verdict} in {len(record.steps)} steps, {record.seconds:.1f} s; "
        f"subgoal completion {record.subgoal_completion:.2f}"
    )
    out.print(f"wrote {out_dir}/episode.gif, {out_dir}/graphs/, {out_dir}/episode.json")


@app.command("eval")
@refuses_bad_input
def evaluate(
    agent: Annotated[str, typer.Option(help="Which agent acts.")] = "oracle",
    sizes: Annotated[str, typer.Option(help="Problem sizes, e.g. 2-6.")] = "2-6",
    goals: Annotated[int, typer.Option(help="Random goals per size.")] = 50,
    seed: Annotated[int, typer.Option(help="Seed of the goals and the episodes.")] = 0,
    goals_file: Annotated[Path | None, typer.Option(help="Goals from a file instead.")] = None,
    workers: Annotated[int, typer.Option(help="Episodes run side by side.")] = 2,
    run_dir: Annotated[
        Path | None, typer.Option("--out", help="Run folder (resumed if it exists).")
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
    markdown: Annotated[
        bool, typer.Option(help="Print a Markdown table (for the README).")
    ] = False,
) -> None:
    """Success rate and subgoal completion per problem size, with the failure taxonomy."""
    from hsgplan.evaluation.protocol import EvalConfig, episode_specs, run_evaluation, summarize

    if workers < 1:
        raise InvalidInputError(f"--workers {workers}: need at least one")
    config = EvalConfig(
        agent, tuple(parse_sizes(sizes)), goals, seed, str(goals_file) if goals_file else None
    )
    from hsgplan.evaluation.protocol import make_agent

    make_agent(agent)
    total = len(episode_specs(config))
    folder = run_dir or Path("runs") / config.run_name()
    with Progress(console=err, transient=True) as progress:
        task = progress.add_task(f"{agent} episodes", total=total)
        records = run_evaluation(config, folder, workers, lambda r: progress.advance(task))
    report = summarize(records) | {"agent": agent, "seed": seed, "run": str(folder)}
    if as_json:
        print(json.dumps(report, indent=2))
        return
    rows = [
        (
            n,
            f"{v['success_rate']:.2f}",
            f"{v['subgoal_completion']:.2f}",
            str(v["episodes"]),
            ", ".join(f"{k} {c}" for k, c in sorted(v["failures"].items())) or "—",
        )
        for n, v in report["by_size"].items()
    ]
    source = f"goals from {goals_file}" if goals_file else f"{goals} goals per size"
    print_table(
        f"{agent}: {source}, seed {seed}",
        ("objects", "success", "subgoal completion", "episodes", "failures"),
        rows,
        markdown,
    )


@bench_app.command("sim")
@refuses_bad_input
def bench_sim(
    sizes: Annotated[str, typer.Option(help="Problem sizes.")] = "2-6",
    episodes: Annotated[int, typer.Option(help="Oracle episodes per size.")] = 5,
    seed: Annotated[int, typer.Option(help="Random seed.")] = 0,
    markdown: Annotated[
        bool, typer.Option(help="Print a Markdown table (for the README).")
    ] = False,
) -> None:
    """Median seconds per primitive (motion planning included) and per oracle episode."""
    from hsgplan.benchmarks.sim import bench_sim as run

    size_list = parse_sizes(sizes)
    with Progress(console=err, transient=True) as progress:
        task = progress.add_task("oracle episodes", total=len(size_list) * episodes)
        rows = run(size_list, episodes, seed, lambda r: progress.advance(task))
    cells = [
        (r.what, str(r.samples), "—" if r.median_seconds is None else f"{r.median_seconds:.3f}")
        for r in rows
    ]
    print_table(
        f"Simulation speed, one core (seed {seed})",
        ("what", "samples", "median s"),
        cells,
        markdown,
    )


@bench_app.command("symbolic")
@refuses_bad_input
def bench_symbolic(
    sizes: Annotated[str, typer.Option(help="Problem sizes, e.g. 2-12.")] = "2-12",
    goals: Annotated[int, typer.Option(help="Goals per size.")] = 20,
    seed: Annotated[int, typer.Option(help="Random seed.")] = 0,
    optimal_max_size: Annotated[
        int, typer.Option(help="Largest size the optimal search is timed on.")
    ] = 8,
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON rows.")] = False,
    markdown: Annotated[
        bool, typer.Option(help="Print a Markdown table (for the README).")
    ] = False,
) -> None:
    """Fast Downward plan time per size: median over the goals, both search configurations."""
    from hsgplan.benchmarks.symbolic import bench_symbolic as run

    size_list = parse_sizes(sizes)
    total = sum(goals * (2 if n <= optimal_max_size else 1) for n in size_list)
    with Progress(console=err, transient=True) as progress:
        task = progress.add_task("planning", total=total)
        rows = run(
            size_list, goals, seed, optimal_max_size, on_problem=lambda: progress.advance(task)
        )
    if as_json:
        print(json.dumps([r.to_json() for r in rows], indent=2))
        return
    title = f"Fast Downward plan time, median over {goals} goals per size (seed {seed})"
    header = ("objects", "planner", "solved", "median s", "median plan length")
    cells = [
        (
            str(r.size),
            r.planner,
            f"{r.solved}/{r.problems}",
            "—" if r.median_seconds is None else f"{r.median_seconds:.3f}",
            "—" if r.median_plan_length is None else f"{r.median_plan_length:g}",
        )
        for r in rows
    ]
    print_table(title, header, cells, markdown)


def print_table(title: str, header: tuple[str, ...], rows: list[tuple[str, ...]], markdown: bool):
    """A Rich table on the terminal, or a Markdown table that the README takes verbatim."""
    if markdown:
        print(f"{title}\n")
        print("| " + " | ".join(header) + " |")
        print("|" + "---:|" * len(header))
        for row in rows:
            print("| " + " | ".join(row) + " |")
        return
    table = Table(title=title)
    for col in header:
        table.add_column(col, justify="right")
    for row in rows:
        table.add_row(*row)
    out.print(table)


def main() -> None:
    try:
        app()
    except BrokenPipeError:
        sys.stderr.close()


if __name__ == "__main__":
    main()
