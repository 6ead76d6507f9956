"""A search over motion-training settings, judged on the training data alone: every
combination of a grid trained once, each keeping its epoch of lowest loss on its held-out
training scenes (`validation`), and the combination whose kept loss is lowest chosen. The test
and tune splits are never read, so the same budget tunes the GNN and the MLP alike
(`hsgplan train motion-search`)."""

from __future__ import annotations

import itertools
import json
from dataclasses import asdict, fields
from pathlib import Path

from hsgplan.domain.checks import read_json
from hsgplan.domain.errors import InvalidInputError
from hsgplan.files import write_atomically
from hsgplan.motion.train import SELECTION, MotionTrainConfig

SEARCH = "search.json"  # the combinations, their kept losses and the one chosen
CHOSEN = "chosen.json"  # the chosen training configuration, ready for `train motion --config`
MAX_COMBINATIONS = 64


def parse_grid(text: str) -> dict[str, list]:
    """`"lr=0.001,0.0003;dropout=0,0.2"` -> {"lr": [0.001, 0.0003], "dropout": [0, 0.2]};
    each name a training setting, each value a JSON number or string, refused in one line."""
    # what the held-out loss judges stays the base's: the data, the loss and the scenes held out
    fixed = {"seed", "data", "primitive", "model", "loss", "validation", "samples", "features",
             "threads", "save_every"}  # fmt: skip
    known = {f.name for f in fields(MotionTrainConfig)} - fixed
    grid: dict[str, list] = {}
    for part in filter(None, (p.strip() for p in text.split(";"))):
        name, eq, values = part.partition("=")
        name = name.strip()
        if not eq or name not in known:
            raise InvalidInputError(
                f"--grid '{part}': need SETTING=V1,V2 with a setting of {', '.join(sorted(known))}"
            )
        if name in grid:
            raise InvalidInputError(f"--grid: '{name}' is given twice")
        grid[name] = [_value(v.strip(), name) for v in values.split(",")]
    if not grid:
        raise InvalidInputError("--grid: name at least one setting and its values")
    return grid


def _value(text: str, name: str):
    try:
        return json.loads(text)
    except ValueError:
        if not text:
            raise InvalidInputError(f"--grid: '{name}' has an empty value") from None
        return text  # a word: a loss or a head


def combinations(base: MotionTrainConfig, grid: dict[str, list]) -> list[MotionTrainConfig]:
    """Every combination of the grid's values on the base configuration, each checked."""
    names = list(grid)
    combos = list(itertools.product(*(grid[n] for n in names)))
    if len(combos) > MAX_COMBINATIONS:
        raise InvalidInputError(f"--grid: {len(combos)} combinations; at most {MAX_COMBINATIONS}")
    if base.validation <= 0:
        raise InvalidInputError(
            "the configuration holds no scenes out (validation 0): the search has nothing to "
            "judge by; give it validation 0.1"
        )
    settings = asdict(base)
    return [
        MotionTrainConfig.from_json({**settings, **dict(zip(names, c, strict=True))})
        for c in combos
    ]


def folder_of(root: Path, index: int) -> Path:
    return Path(root) / f"combination-{index:02d}"


def summarize(root: Path, configs: list[MotionTrainConfig], grid: dict[str, list]) -> dict:
    """Each combination's kept held-out loss and epoch, and the chosen one; written into
    `root` as search.json and chosen.json."""
    rows = []
    for k, config in enumerate(configs):
        selection = read_json(folder_of(root, k) / SELECTION, "training selection")
        kept = min(selection["epochs"], key=lambda h: h["validation_loss"])
        rows.append(
            {
                "combination": k,
                "settings": {n: getattr(config, n) for n in grid},
                "validation_loss": kept["validation_loss"],
                "chosen_epoch": kept["epoch"],
            }
        )
    best = min(rows, key=lambda r: (r["validation_loss"], r["combination"]))
    chosen = configs[best["combination"]]
    report = {"grid": grid, "rows": rows, "chosen": best["combination"]}
    write_atomically(root / SEARCH, json.dumps(report, indent=2) + "\n")
    write_atomically(root / CHOSEN, json.dumps(asdict(chosen), indent=2) + "\n")
    return report
