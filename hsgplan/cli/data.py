"""`hsgplan collect ...`: datasets the learned models are trained on."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.progress import Progress

from hsgplan.cli.common import err, out, refuses_bad_input

app = typer.Typer(no_args_is_help=True, help="Collect datasets (resumable).")


@app.command("demos")
@refuses_bad_input
def demos(
    seed: Annotated[int, typer.Option(help="Seed of the demonstration scenes.")] = 0,
    out_dir: Annotated[
        Path, typer.Option("--out", help="Dataset folder (resumed if it exists).")
    ] = Path("data/demos/v1"),
) -> None:
    """Record the paper's 18 short demonstrations with the oracle in the simulated world."""
    from hsgplan.data.demos import TASKS, collect_demos

    command = f"hsgplan collect demos --seed {seed} --out {out_dir}"
    with Progress(console=err, transient=True) as progress:
        task = progress.add_task("demonstrations", total=len(TASKS))
        done = collect_demos(out_dir, seed, command, lambda d: progress.advance(task))
        progress.update(task, completed=len(TASKS))
    steps = sum(len(d.actions) for d in done)
    out.print(f"{len(done)} demonstrations, {steps} transitions, in {out_dir}")
