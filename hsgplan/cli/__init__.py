"""The `hsgplan` command. It parses, calls the package and prints; nothing else lives here.

One module per group of commands: `symbolic` (plan, goals), `world` (demo, eval world, report),
`scenes` (layouts), `data` (collect), `learn` (train task, eval task, eval reach, labels), `motion`
(train motion, eval motion), `perception` (train perception, eval perception), `bench` and
`bench_motion` (the measurements behind the motion constants); `renamed` refuses the older
spellings.
"""

from __future__ import annotations

import signal
import sys
from importlib.metadata import version
from typing import Annotated

import typer

from hsgplan.cli import (
    bench,
    bench_motion,
    data,
    learn,
    motion,
    perception,
    results,
    runs,
    scenes,
    seeding,
    splits,
    symbolic,
    world,
)
from hsgplan.cli.common import OneLineErrors, Summaries

app = typer.Typer(
    cls=OneLineErrors,
    add_completion=False,
    no_args_is_help=True,
    help="Hierarchical planning with geometric and symbolic scene graphs (kitchen storage).",
)
eval_app = typer.Typer(
    cls=Summaries,
    no_args_is_help=True,
    help="Evaluate: the agent in the world (Table 1), the task planner, f_reach, the motion "
    "generators, f_p.",
)
eval_app.command("world")(world.evaluate)
eval_app.command("task")(learn.eval_task)
eval_app.command("reach")(learn.eval_reach)
eval_app.command("motion")(motion.eval_motion)
eval_app.command("perception")(perception.eval_perception)
eval_app.command("compare")(runs.compare)
eval_app.command("curve")(learn.eval_curve)

app.command()(symbolic.plan)
app.command()(symbolic.goals)
app.command()(world.demo)
app.add_typer(scenes.app, name="scenes")
app.add_typer(eval_app, name="eval")
app.command()(runs.report)
app.add_typer(data.app, name="collect")
app.add_typer(learn.train_app, name="train")
app.add_typer(bench.app, name="bench")
app.add_typer(splits.app, name="splits")
app.command()(seeding.rules)
app.command()(learn.labels)
app.command()(results.results)
bench.app.command("push-reach")(bench_motion.push_reach)
bench.app.command("line-error")(bench_motion.line_error)
bench.app.command("push-settings")(bench_motion.push_settings)
bench.app.command("compare-trials")(bench_motion.compare_trials)
learn.train_app.command("motion")(motion.train_motion)
learn.train_app.command("motion-search")(motion.train_motion_search)


def _print_version(given: bool) -> None:
    if given:
        print(f"hsgplan {version('hsgplan')}")
        raise typer.Exit()


@app.callback()
def _options(
    show_version: Annotated[
        bool,
        typer.Option(
            "--version", help="Print the version and exit.", callback=_print_version, is_eager=True
        ),
    ] = False,
) -> None:
    """Hierarchical planning with geometric and symbolic scene graphs (kitchen storage)."""


learn.train_app.command("perception")(perception.train_perception)


def interrupt_on_terminate() -> None:
    """A `kill` (SIGTERM) interrupts as Ctrl-C does: what a long job does on an interruption
    (its pool closed, the sitting's time added to its run folder) runs, where the default
    would end the process on the spot."""

    def interrupted(signum, frame):
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, interrupted)


def main() -> None:
    interrupt_on_terminate()
    try:
        app()
    except BrokenPipeError:
        sys.stderr.close()


if __name__ == "__main__":
    main()
