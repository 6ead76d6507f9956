"""The `hsgplan` command. It parses, calls the package and prints; nothing else lives here.

One module per group of commands: `symbolic` (plan, goals), `world` (demo, eval, report), `data`
(collect), `learn` (train task, eval-task, eval-reach), `motion` (train motion, eval-motion),
`perception` (train perception, eval-perception), `bench`.
"""

from __future__ import annotations

import sys

import typer

from hsgplan.cli import bench, data, learn, motion, perception, symbolic, world
from hsgplan.cli.common import OneLineErrors

app = typer.Typer(
    cls=OneLineErrors,
    add_completion=False,
    no_args_is_help=True,
    help="Hierarchical planning with geometric and symbolic scene graphs (kitchen storage).",
)
app.command()(symbolic.plan)
app.command()(symbolic.goals)
app.command()(world.demo)
app.command("eval")(world.evaluate)
app.command()(world.report)
app.add_typer(bench.app, name="bench")
app.add_typer(data.app, name="collect")
app.add_typer(learn.train_app, name="train")
app.command("eval-task")(learn.eval_task)
app.command("eval-reach")(learn.eval_reach)
learn.train_app.command("motion")(motion.train_motion)
learn.train_app.command("perception")(perception.train_perception)
app.command("eval-perception")(perception.eval_perception)
app.command("eval-motion")(motion.eval_motion)


def main() -> None:
    try:
        app()
    except BrokenPipeError:
        sys.stderr.close()


if __name__ == "__main__":
    main()
