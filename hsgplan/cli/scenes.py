"""`hsgplan scenes`: random layouts of a scene, written as scene files; `hsgplan scenes check
FILE`: what a scene file's sizes allow."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from hsgplan.cli.common import (
    MarkdownFlag,
    OneLineErrors,
    bounded_option,
    err,
    input_path,
    out,
    out_folder,
    print_table,
    refuses_bad_input,
    shown,
)
from hsgplan.cli.seeding import SplitName
from hsgplan.domain.errors import InvalidInputError

app = typer.Typer(cls=OneLineErrors, invoke_without_command=True)


@app.callback()
@refuses_bad_input
def scenes(
    ctx: typer.Context,
    layouts: Annotated[
        int | None, bounded_option("layouts", "How many layouts (needed to write them).")
    ] = None,
    folder: Annotated[
        Path | None,
        typer.Option(
            "--out",
            help="Folder to write the scene files in (needed to write them).",
            parser=out_folder,
        ),
    ] = None,
    seed: Annotated[
        int | None,
        bounded_option(
            "seed",
            "Random seed; the same seed gives the same layouts (default: 0, or the split's).",
        ),
    ] = None,
    split: Annotated[
        SplitName | None,
        typer.Option(
            help="Draw the layouts from a split's layout seeds (docs/splits.md): test for a "
            "published table of unseen scenes, tune for choosing.",
            metavar="SPLIT",
        ),
    ] = None,
    new_objects: Annotated[
        bool,
        typer.Option(
            "--new-objects", help="Object types never trained on, in place of the scene's."
        ),
    ] = False,
    scene: Annotated[
        Path | None,
        typer.Option(help="The scene to vary (default: scenes/kitchen.toml).", parser=input_path),
    ] = None,
    turn: Annotated[
        float,
        typer.Option(
            help="Turn each shelf by a uniform draw within +-DEG degrees of its yaw (0: as it is).",
            metavar="DEG",
            min=0.0,
            max=180.0,
        ),
    ] = 0.0,
) -> None:
    """Write random layouts of a scene as scene files: its shelves moved and resized (and
    turned), its objects resized (or new ones); the ranges are in docs/scenes.md. `scenes
    check FILE`: what a scene file's sizes allow."""
    if ctx.invoked_subcommand is not None:
        return
    if layouts is None or folder is None:
        raise InvalidInputError(
            "name --layouts N and --out FOLDER to write layouts (or: hsgplan scenes check FILE)"
        )
    from hsgplan.domain.layouts import write_layouts
    from hsgplan.domain.scene_file import read_world
    from hsgplan.evaluation.splits import split_named
    from hsgplan.paths import KITCHEN_SCENE

    if split is not None:
        layouts_of = split_named(split.value).layouts
        seed = layouts_of.start if seed is None else seed
        if seed not in layouts_of:
            raise InvalidInputError(
                f"--seed {seed} is not a {split.value} layout seed "
                f"({layouts_of.start}..{layouts_of.stop - 1})"
            )
    seed = seed or 0
    base = read_world(scene or KITCHEN_SCENE)
    header = f"hsgplan scenes --layouts {layouts} --seed {seed}" + (
        " --new-objects" if new_objects else ""
    )
    if scene is not None:
        header += f" --scene {scene}"
    if turn:
        header += f" --turn {turn:g}"
    written = write_layouts(base, layouts, seed, folder, new_objects, header, turn)
    err.print(f"wrote {len(written)} scene files to {shown(folder)}")


@app.command("check")
@refuses_bad_input
def check(
    file: Annotated[
        Path, typer.Argument(help="The scene file.", parser=input_path, metavar="FILE")
    ],
    markdown: MarkdownFlag = False,
) -> None:
    """What a scene file's sizes allow: each surface's cells and its capacity, the cells the arm
    reaches, the cell objects are counted in, how high a tower may rise and which object sets
    it, where each object fits and whether it carries another. A scene the robot cannot work in is
    refused with every reason (exit code 2)."""
    from hsgplan.domain.scene_file import read_world
    from hsgplan.domain.scene_limits import scene_limits

    world = read_world(file)
    limits = scene_limits(world)
    print_table(
        f"Surfaces of '{world.name}' ({file})",
        ("surface", "kind", "height m", "cells", "objects it holds (cells reached)", "in goals"),
        list(limits.surfaces),
        markdown,
    )
    print_table(
        "Shelf interiors (objects stand in one row, pushed in from the open side)",
        ("shelf", "clearance m", "objects it holds", "types that fit"),
        list(limits.interiors),
        markdown,
    )
    print_table(
        "Object types",
        ("type", "size cm", "carries another", "fits inside"),
        list(limits.objects),
        markdown,
    )
    out.print(limits.cell, highlight=False)
    out.print(limits.tower, highlight=False)
