"""Checkpoint folders, shared by every trainer: `model.safetensors` and `config.json` when
finished, `progress.pt` (model, optimiser, epoch; loaded with weights_only) while training runs.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import torch
from safetensors.torch import load_file, save_file

from hsgplan.domain.errors import InvalidInputError

WEIGHTS, CONFIG, PROGRESS = "model.safetensors", "config.json", "progress.pt"


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
    save_file(model.state_dict(), folder / WEIGHTS)
    (folder / CONFIG).write_text(json.dumps(config, indent=2) + "\n")
    (folder / PROGRESS).unlink(missing_ok=True)


def load_trained(
    folder: Path,
    from_json: Callable[[dict], Any],
    build: Callable[[Any], torch.nn.Module],
    what: str,
) -> tuple[torch.nn.Module, Any]:
    """(network in eval mode, its configuration) from a finished folder; a missing or corrupted
    one raises InvalidInputError with one line."""
    try:
        config = from_json(json.loads((folder / CONFIG).read_text()))
        model = build(config)
        model.load_state_dict(load_file(folder / WEIGHTS))
    except FileNotFoundError:
        raise InvalidInputError(f"no trained {what} in '{folder}'") from None
    except Exception as e:  # corrupted weights or config: one line, not a traceback
        raise InvalidInputError(f"'{folder}' is not a usable checkpoint ({e})") from None
    model.eval()
    return model, config
