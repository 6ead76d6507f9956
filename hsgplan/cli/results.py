"""`hsgplan results`: collect, train and run every published table again (`make results`)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from hsgplan.cli.common import (
    RayAddress,
    check_ray,
    input_path,
    out,
    print_table,
    refuses_bad_input,
)
from hsgplan.domain.errors import InvalidInputError


def _names(text: str) -> list[str]:
    return [n.strip() for n in text.split(",") if n.strip()]


@refuses_bad_input
def results(
    plan: Annotated[
        Path, typer.Option(help="The plan: its steps in order.", parser=input_path)
    ] = Path("configs/results/plan.toml"),
    only: Annotated[
        str, typer.Option(help="Run only these steps (names or tags), comma-separated.")
    ] = "",
    skip: Annotated[
        str,
        typer.Option(help="Leave out steps of these names or tags, comma-separated (slow, rgb)."),
    ] = "",
    ray: RayAddress = None,
    dry_run: Annotated[
        bool,
        typer.Option(
            "--dry-run", help="List the steps and what is finished; run none.", metavar=""
        ),
    ] = False,
    markdown: Annotated[
        bool, typer.Option("--markdown", help="With --dry-run, print Markdown.", metavar="")
    ] = False,
    ship: Annotated[
        bool,
        typer.Option(
            "--ship",
            help="Copy the data and each configuration's own training into data/ and "
            "checkpoints/ (the plan's [[ship]] entries), each once every step that writes it "
            "has finished.",
            metavar="",
        ),
    ] = False,
    paste: Annotated[
        bool,
        typer.Option(
            "--paste",
            help="Then put every finished step's table in its README or docs block, stamped "
            "with its command and commit.",
            metavar="",
        ),
    ] = False,
) -> None:
    """Every published table made again from the repository (configs/results/plan.toml): the
    data collected with today's code, each network trained three times, each table run on the
    test split; resumable, a finished step skipped while its command is unchanged."""
    from hsgplan.runner import results as pipeline

    check_ray(ray)
    if ship:
        _ship(plan)
        return
    steps = pipeline.chosen(pipeline.read_plan(plan), _names(only), _names(skip))
    if dry_run:
        rows = []
        for s in steps:
            made = pipeline.finished(pipeline.OUT, s)
            rows.append(
                (
                    s.name,
                    ", ".join(s.tags) or "—",
                    f"{made['wall_seconds'] / 60:.1f}" if made else "—",
                    made["commit"] if made else "to run",
                )
            )
        done = sum(r[2] != "—" for r in rows)
        title = (
            f"The steps of {plan}: {done} of {len(steps)} finished (wall minutes on this machine)"
        )
        print_table(title, ("step", "tags", "minutes", "finished at"), rows, markdown)
        return
    pipeline.run_plan(steps, ray=ray, echo=lambda line: out.print(line, highlight=False))
    if paste:
        pages = [Path("README.md"), *sorted(Path("docs").glob("*.md"))]
        names = [s.block for s in steps if s.block]
        pasted = pipeline.paste(pages, blocks=names) + pipeline.copy_pictures(steps)
        out.print(f"pasted {', '.join(pasted) or 'nothing'}", highlight=False)


def _ship(plan: Path) -> None:
    from hsgplan.runner import results as pipeline
    from hsgplan.runner.ship import read_shipments
    from hsgplan.runner.ship import ship as copy_over

    steps = pipeline.read_plan(plan)
    entries = read_shipments(plan)
    ready, waiting = [], []
    for entry in entries:
        makers = pipeline.writers(steps, entry.source)
        if not makers:
            raise InvalidInputError(f"'{plan}': no step writes '{entry.source}'")
        unfinished = [s.name for s in makers if pipeline.finished(pipeline.OUT, s) is None]
        (waiting if unfinished else ready).append((entry, unfinished))
    for destination in copy_over([e for e, _ in ready], renames=entries):
        out.print(f"shipped {destination}", highlight=False)
    for entry, unfinished in waiting:
        out.print(f"not yet {entry.destination}: {', '.join(unfinished)} to run", highlight=False)
    if not ready:
        raise InvalidInputError(f"no step of {plan} that makes a shipment has finished")
