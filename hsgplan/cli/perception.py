"""Commands of f_p, the pose estimator: `train perception`."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.progress import Progress

from hsgplan.cli.common import (
    err,
    input_path,
    out,
    out_folder,
    read_config,
    refuses_bad_input,
    shown,
)
from hsgplan.paths import RUNS


@refuses_bad_input
def train_perception(
    config: Annotated[
        Path | None, typer.Option(help="Training configuration (JSON).", parser=input_path)
    ] = None,
    images: Annotated[
        Path | None,
        typer.Option(help="Image collection folder (overrides the config).", parser=input_path),
    ] = None,
    out_dir: Annotated[
        Path,
        typer.Option("--out", help="Checkpoint folder (resumed if it exists).", parser=out_folder),
    ] = RUNS / "train-perception",
) -> None:
    """Train the DOPE-style keypoint network on a synthetic image collection."""
    from hsgplan.perception.train import PerceptionTrainConfig
    from hsgplan.perception.train import train_perception as run

    settings = read_config(config)
    if images is not None:
        settings["images"] = str(images)
    cfg = PerceptionTrainConfig.from_json(settings)
    with Progress(console=err, transient=True) as progress:
        bar = progress.add_task("keypoint network", total=cfg.epochs)

        def on_epoch(epoch: int, loss: float) -> None:
            progress.update(bar, completed=epoch, description=f"keypoint network loss {loss:.4f}")

        run(cfg, out_dir, on_epoch)
    out.print(f"trained the keypoint network into {shown(out_dir)}")
