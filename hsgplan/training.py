"""Training progress, shared by every trainer: `progress.pt` (model, optimiser, epoch and a
fingerprint of the training data; loaded with weights_only) while training runs. A finished
network is written by `hsgplan.checkpoint`.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import torch

from hsgplan.checkpoint import MANIFEST, WEIGHTS, is_finished, non_finite, save_trained
from hsgplan.domain.checks import read_json
from hsgplan.domain.errors import InvalidInputError
from hsgplan.runner.run_folder import write_atomically

PROGRESS = "progress.pt"
TRAIN_CONFIG = "train_config.json"


def claim(out: Path, config: dict, defaults: dict | None = None) -> None:
    """Make `out` the checkpoint folder of a training with `config` (its `train_config.json`).
    Refused in one line, before anything is written: a file, a folder holding other things
    (a dataset, a run, another kind of checkpoint), and a checkpoint trained or in training
    with another configuration. A folder whose training never got as far as saving anything
    (it was refused or diverged) takes the new configuration. A saved configuration lacking a
    setting of `defaults` was trained before the setting existed, with its default."""
    saved = out / TRAIN_CONFIG
    if out.exists() and not out.is_dir():
        raise InvalidInputError(f"'{out}' is a file, not a checkpoint folder")
    if saved.exists() or saved.is_symlink():
        other = {**(defaults or {}), **read_json(saved, "training configuration")}
        # anything trained or in training anywhere below (a task checkpoint keeps its networks
        # in subfolders): another kind of checkpoint is never trained over
        started = any(next(out.rglob(f), None) for f in (MANIFEST, WEIGHTS, PROGRESS))
        if other != config and started:
            raise InvalidInputError(
                f"'{out}' holds a checkpoint trained with another configuration; use another --out"
            )
    elif out.is_dir() and any(out.iterdir()):
        raise InvalidInputError(f"'{out}' holds other files and no checkpoint; use another --out")
    out.mkdir(parents=True, exist_ok=True)
    write_atomically(saved, json.dumps(config, indent=2) + "\n")


def check_loss(loss: float, what: str, epoch: int) -> None:
    """A loss that is not finite ends the training at once: what would be saved is NaN."""
    if not math.isfinite(loss):
        raise InvalidInputError(
            f"training of {what} diverged at epoch {epoch} (loss {loss}); nothing more was "
            "saved (lower lr)"
        )


def finished(folder: Path) -> bool:
    """A network finished earlier: its files match their manifest (a damaged one is redone)."""
    return is_finished(folder)


def resume(folder: Path, model: torch.nn.Module, optim: torch.optim.Optimizer, data: str) -> int:
    """Load the saved progress, if any, into model and optimiser; the epoch to start from.
    Progress made on other training data (`data`, a fingerprint) is refused, never mixed."""
    progress = folder / PROGRESS
    if not progress.exists():
        return 0
    try:
        state = torch.load(progress, weights_only=True)
        saved_data = state.get("data")
        model.load_state_dict(state["model"])
        optim.load_state_dict(state["optim"])
        epoch = int(state["epoch"])
    except Exception as e:  # truncated or foreign file: one line, and nothing else is touched
        raise InvalidInputError(
            f"'{progress}' is not usable training progress ({type(e).__name__}); "
            "delete it to train from the start"
        ) from None
    if saved_data != data:
        raise InvalidInputError(
            f"'{progress}' was made on other training data; delete it to train from the start"
        )
    if non_finite(model.state_dict()):
        raise InvalidInputError(f"'{progress}' holds NaN or infinite weights; delete it")
    return epoch


def save_progress(folder: Path, model, optim, epoch: int, data: str) -> None:
    tmp = folder / "progress.tmp"
    state = {"model": model.state_dict(), "optim": optim.state_dict(), "epoch": epoch}
    torch.save(state | {"data": data}, tmp)
    tmp.replace(folder / PROGRESS)  # a crash mid-write leaves the last good progress


def finish(folder: Path, model: torch.nn.Module, config: dict) -> None:
    """Write the finished network and drop the progress it no longer needs."""
    save_trained(folder, model, config)
    (folder / PROGRESS).unlink(missing_ok=True)
