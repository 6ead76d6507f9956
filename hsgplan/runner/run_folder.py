"""Run folders that survive interruption: a configuration file and an append-only JSON-lines
log of finished work (`episodes.jsonl`), shared by every long job (`runner/items.py`); `collect`
claims its work folder the same way.

A run started again with the same configuration reads back what is logged and skips it; a
folder made with another configuration is refused rather than mixed with.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from hsgplan.domain.errors import InvalidInputError

RESULTS = "episodes.jsonl"
CONFIG = "config.json"
TIMING = "timing.json"


def claim(run_dir: Path, config: dict, refusal: str) -> None:
    """Make `run_dir` the home of a run with `config`; `refusal` is the one-line error when it
    already holds a run with another configuration."""
    run_dir.mkdir(parents=True, exist_ok=True)
    saved = run_dir / CONFIG
    if saved.exists():
        try:
            other = json.loads(saved.read_text())
        except json.JSONDecodeError:
            raise InvalidInputError(f"'{saved}' is not valid JSON") from None
        if other != config:
            raise InvalidInputError(refusal)
    saved.write_text(json.dumps(config) + "\n")


def logged_rows(run_dir: Path) -> list[dict]:
    """The rows logged so far. A line cut short by an interruption is skipped (its episode
    runs again) and ended, so that the next row starts on a line of its own."""
    results = run_dir / RESULTS
    if not results.exists():
        return []
    text = results.read_text()
    if text and not text.endswith("\n"):
        with open(results, "a") as log:
            log.write("\n")
    rows = []
    for line in text.splitlines():
        try:
            rows.append(json.loads(line))
        except json.JSONDecodeError:
            continue
    return rows


def add_wall_seconds(run_dir: Path, seconds: float, workers: int) -> None:
    """Add a session's wall-clock seconds to the folder's timing (`timing.json`), with the
    workers it ran and the cores of the machine: a run interrupted and resumed is timed over
    all its sessions."""
    timing = read_timing(run_dir)
    timing["wall_seconds"] = round(timing["wall_seconds"] + seconds, 3)
    timing["sessions"].append(
        {"seconds": round(seconds, 3), "workers": workers, "cores": os.cpu_count()}
    )
    (run_dir / TIMING).write_text(json.dumps(timing) + "\n")


def read_timing(run_dir: Path) -> dict:
    """`{"wall_seconds": total, "sessions": [...]}` (nothing recorded: 0 and none)."""
    try:
        timing = json.loads((run_dir / TIMING).read_text())
        return {"wall_seconds": float(timing["wall_seconds"]), "sessions": list(timing["sessions"])}
    except (FileNotFoundError, json.JSONDecodeError, KeyError, TypeError, ValueError):
        return {"wall_seconds": 0.0, "sessions": []}
