"""Training progress, shared by every trainer: `progress.safetensors` while training runs.

The progress file holds no code, only data: the model's and the optimiser's tensors in
safetensors, and in its JSON metadata the epoch, a fingerprint of the training data and the
optimiser's structure (its hyperparameters, with each tensor named by its key). It is written
atomically, so a kill leaves the last good progress. A finished network is written by
`hsgplan.checkpoint`.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import torch
from safetensors import safe_open
from safetensors.torch import save

from hsgplan.checkpoint import (
    MANIFEST,
    PROGRESS,
    WEIGHTS,
    is_finished,
    non_finite,
    save_trained,
)
from hsgplan.domain.checks import read_json
from hsgplan.domain.errors import InvalidInputError
from hsgplan.files import write_atomically
from hsgplan.runner.lock import hold_folder
from hsgplan.runner.run_folder import has_files

_STATE = "hsgplan.progress"  # the metadata key holding the JSON half of the progress
OLD_PROGRESS = "progress.pt"  # what older versions saved: a pickle, which is never loaded
TRAIN_CONFIG = "train_config.json"


def claim(out: Path, config: dict, defaults: dict | None = None, data: str | None = None) -> None:
    """Make `out` the checkpoint folder of a training with `config` (its `train_config.json`).
    Refused in one line, before anything is written: a file, a folder holding other things
    (a dataset, a run, another kind of checkpoint), and a checkpoint trained or in training
    with another configuration. A folder whose training never got as far as saving anything
    (it was refused or diverged) takes the new configuration. A saved configuration lacking a
    setting of `defaults` was trained before the setting existed, with its default. With
    `data` (the training data's fingerprint), progress saved anywhere below that is not
    usable or was made on other data is refused here too. The caller is the folder's one
    writer from here until it ends (`runner/lock.py`)."""
    _check_claim(out, config, defaults, data)
    hold_folder(out)
    _check_claim(out, config, defaults, data)  # again: it may have changed hands
    write_atomically(out / TRAIN_CONFIG, json.dumps(config, indent=2) + "\n")


def hold(folder: Path) -> None:
    """Make this process the one writer of one network's folder of a checkpoint that another
    process claimed (its networks trained side by side)."""
    hold_folder(folder)


def _check_claim(out: Path, config: dict, defaults: dict | None, data: str | None) -> None:
    """`claim`'s refusals, without writing anything."""
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
    elif out.is_dir() and has_files(out):
        raise InvalidInputError(f"'{out}' holds other files and no checkpoint; use another --out")
    if data is not None and out.is_dir():
        for progress in sorted(out.rglob(PROGRESS)):
            _check_progress(progress, data)
        if old := next(out.rglob(OLD_PROGRESS), None):
            raise InvalidInputError(
                f"'{old}' is training progress in an older format (a pickle, never read); "
                "delete it to train from the start"
            )


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


def _encode(value, key: str, tensors: dict[str, torch.Tensor]):
    """`value` (a state dict, nested) as JSON, its tensors moved into `tensors` by key."""
    if isinstance(value, torch.Tensor):
        tensors[key] = value.detach().clone().contiguous()  # shared storage cannot be saved
        return {"$tensor": key}
    if isinstance(value, dict):  # keys may be integers (an optimiser's parameter ids)
        return {"$dict": [[k, _encode(v, f"{key}.{k}", tensors)] for k, v in value.items()]}
    if isinstance(value, tuple):
        return {"$tuple": [_encode(v, f"{key}.{i}", tensors) for i, v in enumerate(value)]}
    if isinstance(value, list):
        return [_encode(v, f"{key}.{i}", tensors) for i, v in enumerate(value)]
    if value is None or isinstance(value, bool | int | float | str):
        return value
    raise TypeError(f"{key}: a {type(value).__name__} has no place in training progress")


def _decode(value, tensors: dict[str, torch.Tensor]):
    if isinstance(value, list):
        return [_decode(v, tensors) for v in value]
    if not isinstance(value, dict):
        return value
    if "$tensor" in value:
        return tensors[value["$tensor"]]
    if "$tuple" in value:
        return tuple(_decode(v, tensors) for v in value["$tuple"])
    return {k: _decode(v, tensors) for k, v in value["$dict"]}


def _read_progress(path: Path) -> dict:
    with safe_open(path, framework="pt") as f:
        tensors = {k: f.get_tensor(k) for k in f.keys()}  # noqa: SIM118 (not a mapping)
        state = json.loads((f.metadata() or {})[_STATE])
    return _decode(state, tensors)


def _unusable(progress: Path, e: Exception) -> InvalidInputError:
    return InvalidInputError(
        f"'{progress}' is not usable training progress ({type(e).__name__}); "
        "delete it to train from the start"
    )


def _check_progress(progress: Path, data: str) -> dict:
    """The saved state of a progress file made on `data`; anything else refused in one line
    (a truncated or foreign file, a pickle: nothing is ever unpickled)."""
    try:
        state = _read_progress(progress)
        if not isinstance(state, dict):
            raise TypeError("not a saved state")
    except Exception as e:
        raise _unusable(progress, e) from None
    if state.get("data") != data:
        raise InvalidInputError(
            f"'{progress}' was made on other training data; delete it to train from the start"
        )
    return state


def resume(folder: Path, model: torch.nn.Module, optim: torch.optim.Optimizer, data: str) -> int:
    """Load the saved progress, if any, into model and optimiser; the epoch to start from.
    Progress made on other training data (`data`, a fingerprint) is refused, never mixed."""
    return resume_with(folder, model, optim, data)[0]


def resume_with(
    folder: Path, model: torch.nn.Module, optim: torch.optim.Optimizer, data: str
) -> tuple[int, dict]:
    """`resume`, and what the trainer saved beside the weights (`save_progress`'s `extra`)."""
    progress = folder / PROGRESS
    if not progress.exists():
        return 0, {}
    state = _check_progress(progress, data)
    try:
        model.load_state_dict(state["model"])
        optim.load_state_dict(state["optim"])
        epoch = int(state["epoch"])
        extra = state.get("extra") or {}
        if not isinstance(extra, dict):
            raise TypeError("extra: not a mapping")
    except Exception as e:  # another network's progress: one line, and nothing is touched
        raise _unusable(progress, e) from None
    if non_finite(model.state_dict()):
        raise InvalidInputError(f"'{progress}' holds NaN or infinite weights; delete it")
    return epoch, extra


def save_progress(
    folder: Path, model, optim, epoch: int, data: str, extra: dict | None = None
) -> None:
    """The last finished epoch, written whole (a crash mid-write leaves the last good one);
    `extra` (tensors, numbers, text) comes back from `resume_with`."""
    tensors: dict[str, torch.Tensor] = {}
    state = {"model": model.state_dict(), "optim": optim.state_dict(), "epoch": epoch}
    if extra:
        state["extra"] = extra
    meta = json.dumps(_encode(state | {"data": data}, "state", tensors))
    write_atomically(folder / PROGRESS, save(tensors, metadata={_STATE: meta}))


def finish(folder: Path, model: torch.nn.Module, config: dict) -> None:
    """Write the finished network and drop the progress it no longer needs."""
    save_trained(folder, model, config)
    (folder / PROGRESS).unlink(missing_ok=True)
