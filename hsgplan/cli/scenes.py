"""`hsgplan scenes`: random layouts of a scene, written as scene files."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from hsgplan.cli.common import (
    bounded_option,
    err,
    input_path,
    out_folder,
    refuses_bad_input,
    shown,
)
from hsgplan.cli.seeding import SplitName
from hsgplan.domain.errors import InvalidInputError


@refuses_bad_input
def scenes(
    layouts: Annotated[int, bounded_option("layouts", "How many layouts.")],
    out: Annotated[
        Path, typer.Option("--out", help="Folder to write the scene files in.", parser=out_folder)
    ],
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
) -> None:
    """Write random layouts of a scene as scene files: its shelves moved and resized, its
    objects resized (or new ones); the ranges are in docs/scenes.md."""
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
    written = write_layouts(base, layouts, seed, out, new_objects, header)
    err.print(f"wrote {len(written)} scene files to {shown(out)}")
