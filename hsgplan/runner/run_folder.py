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

from hsgplan.domain.checks import read_json
from hsgplan.domain.errors import InvalidInputError, a
from hsgplan.files import write_atomically
from hsgplan.runner.lock import LOCK, hold_folder

RESULTS = "episodes.jsonl"
CONFIG = "config.json"
TIMING = "timing.json"


def claim(run_dir: Path, kind: str, config: dict, refusal: str) -> None:
    """Make `run_dir` the home of a `kind` run with `config`. Refused in one line, before
    anything is written: a folder of another kind (a checkpoint, a dataset, another command's
    run), a folder holding files but no run, and a run with another configuration (`refusal`,
    which says what to do), and a folder another process is writing (`runner/lock.py`): the
    caller is its one writer from here until it ends."""
    check_claim(run_dir, kind, config, refusal)
    hold_folder(run_dir)
    if not check_claim(run_dir, kind, config, refusal):  # again: it may have changed hands
        write_atomically(run_dir / CONFIG, json.dumps({"kind": kind} | config) + "\n")


def check_claim(run_dir: Path, kind: str, config: dict, refusal: str) -> bool:
    """`claim`'s refusals without writing anything; whether the folder is already this run's."""
    config = {"kind": kind} | config
    saved = run_dir / CONFIG
    if run_dir.exists() and not run_dir.is_dir():
        raise InvalidInputError(f"'{run_dir}' is a file, not a run folder")
    if saved.exists() or saved.is_symlink():
        other = read_json(saved, "run configuration")
        if other.get("kind") != kind:
            what = f"{a(other['kind'])} run" if isinstance(other.get("kind"), str) else "no run"
            raise InvalidInputError(
                f"'{run_dir}' is not {a(kind)} run folder (it holds {what}); use another --out"
            )
        # A setting added since the folder was claimed, at its default of None (which keeps
        # what runs did before it existed: `scene` None is the kitchen), is no difference.
        if other != {k: v for k, v in config.items() if k in other or v is not None}:
            raise InvalidInputError(refusal)
        return True
    if run_dir.is_dir() and has_files(run_dir):
        raise InvalidInputError(
            f"'{run_dir}' holds other files and no {kind} run; use another --out"
        )
    return False


def check_own(folder: Path, marker: str, kind: str) -> None:
    """Refuse a folder that holds files but not `marker`, the file every `kind` folder has:
    a folder another command made is never written into."""
    if folder.exists() and not folder.is_dir():
        raise InvalidInputError(f"'{folder}' is a file, not a folder")
    if folder.is_dir() and has_files(folder) and not (folder / marker).is_file():
        raise InvalidInputError(
            f"'{folder}' holds other files and no {kind} ({marker}); use another --out"
        )


def has_files(folder: Path) -> bool:
    """Whether `folder` holds anything but what a run that was killed leaves behind: its lock
    (`runner/lock.py`) and a temporary file it was writing (`hsgplan.files`)."""
    return any(not _leftover(p.name) for p in folder.iterdir())


def _leftover(name: str) -> bool:
    return name == LOCK or (name.startswith(".") and ".tmp" in name)


def logged_rows(run_dir: Path) -> list[dict]:
    """The rows logged so far. A line cut short by an interruption is skipped (its episode
    runs again) and ended, so that the next row starts on a line of its own."""
    results = run_dir / RESULTS
    if not results.exists():
        return []
    if not results.is_file():
        raise InvalidInputError(f"'{results}' is not a file; this run folder is damaged")
    text = results.read_bytes().decode("utf-8", errors="replace")
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
    """Add one sitting's wall-clock seconds to the folder's timing (`timing.json`, a list
    `sittings` of them), with the workers it ran and the cores of the machine: a run
    interrupted and resumed is timed over all its sittings."""
    timing = read_timing(run_dir)
    timing["wall_seconds"] = round(timing["wall_seconds"] + seconds, 3)
    timing["sittings"].append(
        {"seconds": round(seconds, 3), "workers": workers, "cores": os.cpu_count()}
    )
    write_atomically(run_dir / TIMING, json.dumps(timing) + "\n")


def read_timing(run_dir: Path) -> dict:
    """`{"wall_seconds": total, "sittings": [...]}` (nothing recorded: 0 and none)."""
    try:
        timing = json.loads((run_dir / TIMING).read_text())
        return {"wall_seconds": float(timing["wall_seconds"]), "sittings": sittings(timing)}
    except (OSError, json.JSONDecodeError, KeyError, TypeError, ValueError):
        return {"wall_seconds": 0.0, "sittings": []}


def sittings(timing: dict) -> list[dict]:
    """The timed sittings a timing (or an eval summary's method, which carries one) lists.
    Folders and summaries written before the list was named `sittings` call it `sessions`."""
    older = "sessions" in timing and "sittings" not in timing
    return list(timing["sessions"] if older else timing["sittings"])
