"""Training progress, shared by every trainer: `progress.pt` (model, optimiser, epoch; loaded
with weights_only) while training runs. A finished network is written by `hsgplan.checkpoint`.
"""

from __future__ import annotations

from pathlib import Path

import torch

from hsgplan.checkpoint import WEIGHTS, save_trained
from hsgplan.domain.errors import InvalidInputError

PROGRESS = "progress.pt"


def finished(folder: Path) -> bool:
    return (folder / WEIGHTS).exists()


def resume(folder: Path, model: torch.nn.Module, optim: torch.optim.Optimizer) -> int:
    """Load the saved progress, if any, into model and optimiser; the epoch to start from."""
    progress = folder / PROGRESS
    if not progress.exists():
        return 0
    try:
        state = torch.load(progress, weights_only=True)
        model.load_state_dict(state["model"])
        optim.load_state_dict(state["optim"])
        return int(state["epoch"])
    except Exception as e:  # truncated or foreign file: one line, and nothing else is touched
        raise InvalidInputError(
            f"'{progress}' is not usable training progress ({type(e).__name__}); "
            "delete it to train from the start"
        ) from None


def save_progress(folder: Path, model, optim, epoch: int) -> None:
    tmp = folder / "progress.tmp"
    torch.save({"model": model.state_dict(), "optim": optim.state_dict(), "epoch": epoch}, tmp)
    tmp.replace(folder / PROGRESS)  # a crash mid-write leaves the last good progress


def finish(folder: Path, model: torch.nn.Module, config: dict) -> None:
    """Write the finished network and drop the progress it no longer needs."""
    save_trained(folder, model, config)
    (folder / PROGRESS).unlink(missing_ok=True)
