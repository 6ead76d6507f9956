"""Finished networks on disk: a folder with `model.safetensors`, `config.json` (the network's
configuration) and `manifest.json` (the size and SHA-256 of both). Inference reads them from
here and never imports training code; the trainers write them through `hsgplan.training`.

Writes are atomic (a temporary file renamed) and the manifest is written last, so a folder is
finished exactly when its manifest matches its files: an interrupted save, a truncated or
replaced file, or weights that are not finite are refused on load in one line.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import torch
from safetensors.torch import load_file, save

from hsgplan.domain.errors import InvalidInputError
from hsgplan.files import write_atomically
from hsgplan.paths import shipped

WEIGHTS, CONFIG, MANIFEST = "model.safetensors", "config.json", "manifest.json"
PROGRESS = "progress.safetensors"  # an unfinished training's last epoch (`hsgplan.training`)


def _digest(path: Path) -> dict:
    data = path.read_bytes()
    return {"bytes": len(data), "sha256": hashlib.sha256(data).hexdigest()}


def non_finite(state: dict[str, torch.Tensor]) -> list[str]:
    """The tensors of a state dict holding NaN or infinity."""
    return [k for k, t in state.items() if t.is_floating_point() and not torch.isfinite(t).all()]


def save_trained(folder: Path, model: torch.nn.Module, config: dict) -> None:
    """Write a finished network; non-finite weights (a diverged training) are refused."""
    state = model.state_dict()
    if bad := non_finite(state):
        raise InvalidInputError(
            f"training diverged: {bad[0]} holds NaN or infinity; nothing was saved in "
            f"'{folder}' (lower lr)"
        )
    (folder / MANIFEST).unlink(missing_ok=True)  # unfinished until the manifest is back
    write_atomically(folder / WEIGHTS, save(state))  # our writer: a full disk is an OSError
    write_atomically(folder / CONFIG, json.dumps(config, indent=2) + "\n")
    write_manifest(folder)


def write_manifest(folder: Path) -> None:
    """The size and checksum of a network's files, the mark of a finished folder."""
    manifest = {name: _digest(folder / name) for name in (WEIGHTS, CONFIG)}
    write_atomically(folder / MANIFEST, json.dumps(manifest, indent=2) + "\n")


def verify(folder: Path, what: str = "network") -> None:
    """Refuse, in one line, a folder whose files are missing or do not match its manifest."""
    for name in (WEIGHTS, CONFIG, MANIFEST):
        if not (folder / name).is_file():
            raise InvalidInputError(f"no trained {what} in '{folder}' ({name} is missing)")
    try:
        manifest = json.loads((folder / MANIFEST).read_bytes())
        expected = {name: dict(manifest[name]) for name in (WEIGHTS, CONFIG)}
    except (ValueError, KeyError, TypeError, OSError):
        raise InvalidInputError(f"'{folder / MANIFEST}' is damaged; train it again") from None
    for name in (WEIGHTS, CONFIG):
        if _digest(folder / name) != expected[name]:
            raise InvalidInputError(
                f"'{folder / name}' does not match its manifest (damaged or replaced); "
                "train it again"
            )


def is_finished(folder: Path) -> bool:
    try:
        verify(folder)
    except InvalidInputError:
        return False
    return True


def load_trained(
    folder: Path,
    from_json: Callable[[dict], Any],
    build: Callable[[Any], torch.nn.Module],
    what: str,
) -> tuple[torch.nn.Module, Any]:
    """(network in eval mode, its configuration) from a finished folder, found as
    `hsgplan.paths.shipped` finds it; a missing, damaged or non-finite one raises
    InvalidInputError with one line."""
    folder = shipped(folder)
    verify(folder, what)
    try:
        config = from_json(json.loads((folder / CONFIG).read_bytes()))
        model = build(config)
        state = load_file(folder / WEIGHTS)
        model.load_state_dict(state)
    except InvalidInputError as e:
        raise InvalidInputError(f"'{folder}' is not a usable checkpoint ({e})") from None
    except Exception as e:  # a foreign config or weights of another shape: one line
        first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        raise InvalidInputError(f"'{folder}' is not a usable checkpoint ({first})") from None
    if bad := non_finite(state):
        raise InvalidInputError(f"'{folder}' holds NaN or infinite weights ({bad[0]})")
    model.eval()
    return model, config


def fingerprint(folders: Iterable[Path]) -> str:
    """One SHA-256 over every file of these folders or files (folders recursively, in name
    order): a run folder records it, so that results of one checkpoint (or data) are never
    resumed under another."""
    h = hashlib.sha256()
    for folder in sorted({shipped(f) for f in folders}):
        if folder.is_file():
            files, folder = [folder], folder.parent
        elif folder.is_dir():
            files = sorted(p for p in folder.rglob("*") if p.is_file())
        else:
            files = []
        for path in files:
            if path.name.startswith(".") or path.name == PROGRESS or path.suffix in (".pt", ".tmp"):
                continue  # training leftovers are not what a run is evaluated with
            h.update(str(path.relative_to(folder)).encode() + b"\0")
            h.update(hashlib.sha256(path.read_bytes()).digest())
    return h.hexdigest()
