"""Finished networks on disk: a folder with `model.safetensors` and `config.json` (the network's
configuration). Inference reads them from here and never imports training code; the trainers
write them through `hsgplan.training`.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import torch
from safetensors.torch import load_file, save_file

from hsgplan.domain.errors import InvalidInputError
from hsgplan.paths import shipped

WEIGHTS, CONFIG = "model.safetensors", "config.json"


def save_trained(folder: Path, model: torch.nn.Module, config: dict) -> None:
    save_file(model.state_dict(), folder / WEIGHTS)
    (folder / CONFIG).write_text(json.dumps(config, indent=2) + "\n")


def load_trained(
    folder: Path,
    from_json: Callable[[dict], Any],
    build: Callable[[Any], torch.nn.Module],
    what: str,
) -> tuple[torch.nn.Module, Any]:
    """(network in eval mode, its configuration) from a finished folder, found as
    `hsgplan.paths.shipped` finds it; a missing or corrupted one raises InvalidInputError with
    one line."""
    folder = shipped(folder)
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
