"""A hostile case, the setup steps that make its folder, and the inputs the cases share.

A case is one `hsgplan` command line with a bad input in it (an output path that cannot be
written, a count no machine finishes, a damaged checkpoint, Rich markup in an echoed value,
...), run in a fresh folder of its own that its setup steps fill first.
"""

from __future__ import annotations

import json
import os
import shlex
import shutil
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

SHIPPED = ("checkpoints", "data")

Setup = Callable[[Path, Path], None]  # (the case's cwd, the shared HSGPLAN_HOME copy)


@dataclass
class Case:
    command: str  # the row of the table: "eval", "collect place", ...
    name: str  # what is hostile about it
    args: list[str]  # after `hsgplan`
    setup: list[Setup] = field(default_factory=list)  # what the cwd holds before the run
    echo: str | None = None  # text the error line must quote verbatim (Rich markup cases)
    own_home: bool = False  # HSGPLAN_HOME = the cwd (which then holds its own shipped copy)
    # Data-loss cases: only these folders (in the cwd) must stay as they were; the command may
    # refuse, or run (exit 0) and write elsewhere, e.g. into a fresh `runs/` folder.
    keep: tuple[str, ...] = ()
    file_bytes: int | None = None  # the largest file it may write (a full disk, as ulimit -f)

    @property
    def id(self) -> str:
        return f"{self.command}: {self.name}"


def case(command: str, name: str, args: str | list, *setup: Setup, **kw) -> Case:
    """A case; `args` is a shell-like string (split as the shell would) or a list."""
    argv = shlex.split(args) if isinstance(args, str) else [str(a) for a in args]
    return Case(command, name, argv, list(setup), **kw)


def table(text: str) -> list[list[str]]:
    """The rows of a `|`-separated text table, cells stripped; blank lines skipped."""
    return [[c.strip() for c in line.split("|")] for line in text.strip().splitlines()]


NUMBERS = {"1e6": 10**6, "1e9": 10**9, "1e12": 10**12, "1e15": 10**15, "2**70": 2**70}


def number(token: str) -> str:
    return str(NUMBERS.get(token, token))


# Setup steps, each a function of (cwd, home).


def write(rel: str, data: bytes | str) -> Setup:
    def step(cwd: Path, home: Path) -> None:
        p = cwd / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_bytes(data.encode() if isinstance(data, str) else data)

    return step


def write_json(rel: str, value) -> Setup:
    return write(rel, json.dumps(value) + "\n")


def mkdir(rel: str) -> Setup:
    return lambda cwd, home: (cwd / rel).mkdir(parents=True, exist_ok=True)


def symlink(rel: str, target: str) -> Setup:
    return lambda cwd, home: os.symlink(target, cwd / rel)


def fifo(rel: str) -> Setup:
    return lambda cwd, home: os.mkfifo(cwd / rel)


def remove(rel: str) -> Setup:
    def step(cwd: Path, home: Path) -> None:
        p = cwd / rel
        shutil.rmtree(p) if p.is_dir() else p.unlink()

    return step


def dir_for(rel: str) -> list[Setup]:
    """A directory where the file `rel` was."""
    return [remove(rel), mkdir(rel)]


def truncate(rel: str, size: int = 100) -> Setup:
    def step(cwd: Path, home: Path) -> None:
        p = cwd / rel
        p.write_bytes(p.read_bytes()[:size])

    return step


def copy_shipped(src: str, dst: str) -> Setup:
    """A copy of a shipped file or folder (from the run's home copy) at `dst` in the cwd."""

    def step(cwd: Path, home: Path) -> None:
        (cwd / dst).parent.mkdir(parents=True, exist_ok=True)
        if (home / src).is_dir():
            shutil.copytree(home / src, cwd / dst)
        else:
            shutil.copy2(home / src, cwd / dst)

    return step


def own_home() -> list[Setup]:
    return [copy_shipped(name, name) for name in SHIPPED]


# Shared bits of input.

GOAL2 = "In(tomato_soup, shelf_a) & On(cream_cheese, shelf_a)"
GOALS_TEXT = f"{GOAL2}\nOn(popcorn, shelf_a) & On(butter, shelf_b)\n"
LATIN1 = b"\xe9t\xe9 \xff\xfe caf\xe9"  # not UTF-8
JUNK = bytes(range(256)) * 8
KEEP = write("taken.txt", "keep me\n")
TINY_TASK = {"epochs": 1, "copies": 0, "vary": False, "reach": "alterations"}
TINY_TASK |= {"reach_singles": 1, "rounds": 1, "hidden": 8}
TINY_MOTION = {"epochs": 1, "samples": 64, "hidden": 16, "embed": 8, "rounds": 1, "loss": "ce"}
EVAL_CONFIG = {"kind": "eval", "agent": "oracle", "sizes": [2], "goals": 1, "seed": 0}
EVAL_CONFIG |= {"goals_file": None, "repeats": 1, "checkpoint": None, "motion_checkpoints": None}


def tiny_config(base: dict, key: str | None = None, raw: str | None = None) -> str:
    """`base` as JSON text with `key` set to the raw JSON text `raw` (NaN and Infinity too)."""
    items = [f"{json.dumps(k)}: {json.dumps(v)}" for k, v in base.items() if k != key]
    if key is not None:
        items.append(f"{json.dumps(key)}: {raw}")
    return "{" + ", ".join(items) + "}\n"


def eval_run(rel: str) -> list[Setup]:
    """A folder shaped like an eval run of the oracle: `oracle/config.json`,
    `oracle/episodes.jsonl`, `summary.json` (`runner/run_folder.py`, `evaluation/table1.py`)."""
    row = {"key": f"2/0/0/{GOAL2}", "result": {"goal": GOAL2, "success": True}}
    return [
        write_json(f"{rel}/oracle/config.json", EVAL_CONFIG),
        write(f"{rel}/oracle/episodes.jsonl", json.dumps(row) + "\n"),
        write_json(f"{rel}/summary.json", {"methods": {}, "goals": 1, "run": rel}),
    ]


# Base command lines: valid and small, so that only the hostile part is wrong (and a bad input
# that is accepted shows as "accepted" rather than as a long run).
TASK_TINY = write("tiny.json", tiny_config(TINY_TASK))
MOTION_TINY = write("tiny.json", tiny_config(TINY_MOTION))
BASE: dict[str, tuple[str, list[Setup]]] = {
    "goals": ("goals --objects 2 --goals 1", []),
    "demo": ("demo --agent oracle --objects 2", []),
    "eval": ("eval world --sizes 2 --goals 1 --workers 1", []),
    "eval task": ("eval task --sizes 2 --goals 1 --workers 1", []),
    "eval motion": ("eval motion --trials 1 --workers 1 --primitives place", []),
    "collect demos": ("collect demos", []),
    "collect place": ("collect place --samples 1 --workers 1", []),
    "collect push": ("collect push --samples 1 --workers 1", []),
    "collect reach": ("collect reach --states 1 --workers 1", []),
    "train task": ("train task --config tiny.json", [TASK_TINY]),
    "train motion": ("train motion --config tiny.json", [MOTION_TINY]),
    "bench timing": ("bench timing --sizes 2 --goals 1 --workers 1", []),
    "collect images": ("collect images --samples 1 --workers 1", []),
    "train perception": ("train perception --images imgs", [mkdir("imgs")]),
}


def base(command: str, more: str = "") -> str:
    return f"{BASE[command][0]} {more}".strip()
