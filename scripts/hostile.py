"""Hostile input against every `hsgplan` command: is each bad input refused cleanly?

Usage: python scripts/hostile.py [--jobs 2] [--timeout 20] [--only SUBSTRING] [--list] [--json]
                                 [--failures] [--mem-gb 4] [--keep]

Every case is a bad input (an output path that cannot be written, a count no machine finishes,
a damaged checkpoint, Rich markup in an echoed value, ...) run as a subprocess of the venv's
`hsgplan`. A clean refusal: exit code 2; stderr holds exactly one non-empty line and it starts
with `error:` (quoting the hostile text verbatim where the case says so); it finishes within the
timeout; nothing new appears in the case's scratch folder and nothing the case put there
changes. Each case is classified as one of

    refused    the clean refusal above
    traceback  "Traceback" in stdout or stderr, or exit code 1 with a Python exception
    hang       still running at the timeout (killed with its process group)
    accepted   exit code 0, or files created or changed (bad input taken, data touched)

A data-loss case (a default output folder that holds the shipped data) is clean, and counted
under "refused", when it is refused or when it exits 0 leaving the shipped copy unchanged.
    usage-box  click/Typer's framed, multi-line usage error
    other      anything else (several stderr lines, input not quoted verbatim, ...)

Each case runs in a fresh scratch folder (its cwd) under one temporary root, with
HSGPLAN_HOME pointing at a copy of the repository's `checkpoints/` and `data/` made once per run
(cases about the default output folders get a copy of their own in their cwd, and HSGPLAN_HOME
pointing there), PYTHONHASHSEED unset, stdin closed, and `ulimit -v` of --mem-gb so that a huge
count cannot take the machine down. Nothing under the repository is ever written.

Output: a Markdown table of the classes per command, then totals (--json: one JSON object with
the counts and the failing cases; --failures: every failing case with its argv and the first
and last lines of its stderr). Exit code 0 when every case is refused cleanly, 1 otherwise.
"""

from __future__ import annotations

import argparse
import contextlib
import hashlib
import json
import os
import re
import shlex
import shutil
import signal
import stat
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
HSGPLAN = REPO / ".venv" / "bin" / "hsgplan"
SHIPPED = ("checkpoints", "data")
KINDS = ("refused", "traceback", "hang", "accepted", "usage-box", "other")
COMMANDS = (
    "plan",
    "goals",
    "demo",
    "eval",
    "report",
    "eval-task",
    "eval-reach",
    "eval-motion",
    "bench sim",
    "bench symbolic",
    "bench task",
    "bench timing",
    "bench collect",
    "collect demos",
    "collect place",
    "collect push",
    "collect reach",
    "train task",
    "train motion",
    "collect images",
    "train perception",
    "eval-perception",
)

# ---------------------------------------------------------------------------------------------
# Cases
# ---------------------------------------------------------------------------------------------

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
    "goals": ("goals --objects 2 --count 1", []),
    "demo": ("demo --agent oracle --objects 2", []),
    "eval": ("eval --sizes 2 --goals 1 --workers 1", []),
    "eval-task": ("eval-task --sizes 2 --goals 1 --workers 1", []),
    "eval-motion": ("eval-motion --trials 1 --workers 1 --primitives place", []),
    "collect demos": ("collect demos", []),
    "collect place": ("collect place --samples 1 --workers 1", []),
    "collect push": ("collect push --samples 1 --workers 1", []),
    "collect reach": ("collect reach --states 1 --workers 1", []),
    "train task": ("train task --config tiny.json", [TASK_TINY]),
    "train motion": ("train motion --config tiny.json", [MOTION_TINY]),
    "bench timing": ("bench timing --sizes 2 --goals 1 --workers 1", []),
    "collect images": ("collect images --count 1 --workers 1", []),
    "train perception": ("train perception --images imgs", [mkdir("imgs")]),
}


def base(command: str, more: str = "") -> str:
    return f"{BASE[command][0]} {more}".strip()


def output_cases() -> list[Case]:
    """--out that cannot (or must not) be written, for every command with --out."""
    cases = []
    for command, (args, setup) in BASE.items():
        bad = [
            ("an existing file", "taken.txt", [KEEP]),
            ("/proc/x", "/proc/x", []),
            ("/dev/full", "/dev/full", []),
            ("under an existing file", "taken.txt/sub", [KEEP]),
            ("''", "''", []),
        ]
        # (a goal file under a missing folder is fine: its folders are made)
        for label, path, more in bad:
            cases.append(case(command, f"--out {label}", f"{args} --out {path}", *setup, *more))
    return cases


# command | base command line | option | values (ALL: -1 0 1e9 1e12 2**70)
COUNTS = """
goals          | goals --objects 2                                    | --count     | ALL
eval           | eval --sizes 2 --workers 1                           | --goals     | ALL
eval           | eval --sizes 2 --goals 1 --workers 1                 | --repeats   | 0
eval-task      | eval-task --sizes 2 --workers 1                      | --goals     | -1 2**70
collect place  | collect place --workers 1 --out ds                   | --samples   | ALL
collect push   | collect push --workers 1 --out ds                    | --samples   | -1 1e12
collect place  | collect place --samples 1 --workers 1 --out ds       | --tasks-per-chunk | 0
collect reach  | collect reach --workers 1 --out ds                   | --states    | ALL
eval-motion    | eval-motion --workers 1 --primitives place           | --trials    | ALL
bench sim      | bench sim --sizes 2                                  | --episodes  | -1 1e12
bench symbolic | bench symbolic --sizes 2                             | --goals     | -1 1e12
bench symbolic | bench symbolic --sizes 2 --goals 1                   | --optimal-max-size | -1
bench task     | bench task --sizes 2                                 | --goals     | -1 1e12
bench timing   | bench timing --sizes 2 --workers 1                   | --goals     | -1 1e12
bench collect  | bench collect --workers 1 --primitives place         | --samples   | -1 1e12
report         | report run                                           | --failures  | -1
collect images | collect images --workers 1 --out ds                  | --count     | ALL
eval-perception | eval-perception                                     | --scenes    | ALL
"""
# a small count each: a huge pool for one item would still start one process
WORKERS = """
eval           | eval --sizes 2 --goals 1
eval-task      | eval-task --sizes 2 --goals 1
eval-motion    | eval-motion --trials 1 --primitives place
collect place  | collect place --samples 1 --out ds
collect push   | collect push --samples 1 --out ds
collect reach  | collect reach --states 1 --out ds
collect images | collect images --count 1 --out ds
"""
SEEDS = """
goals          | goals --objects 2 --count 1
demo           | demo --agent oracle --objects 2 --out pics
eval           | eval --sizes 2 --goals 1 --workers 1
eval-task      | eval-task --sizes 2 --goals 1 --workers 1
collect demos  | collect demos --out ds
collect place  | collect place --samples 1 --workers 1 --out ds
collect reach  | collect reach --states 1 --workers 1 --out ds
train task     | train task --config tiny.json --out ck
collect images | collect images --count 1 --workers 1 --out ds
eval-perception | eval-perception --scenes 1
"""
MALFORMED = """
goals          | goals --objects 2 --count abc
goals          | goals --objects 2 --count 1.5
goals          | goals --objects 2 --count ''
eval           | eval --sizes 2 --goals 1 --workers 1e3
collect place  | collect place --samples 0x10 --out ds
bench timing   | bench timing --sizes 2 --goals 1 --workers 1 --search pddl
"""
# command | base command line | --sizes values (a space-separated list; '' is the empty value)
SIZES = """
eval           | eval --goals 1 --workers 1                 | '' 6-2 0 13 2-1000000000
eval-task      | eval-task --goals 1 --workers 1            | '' 6-2 13 2-1000000000
bench sim      | bench sim --episodes 1                     | 6-2 2-1000000000
bench symbolic | bench symbolic --goals 1                   | 6-2 2-1000000000
bench task     | bench task --goals 1                       | 13 2-1000000000
bench timing   | bench timing --goals 1 --workers 1         | 6-2 2-1000000000
"""


def number_cases() -> list[Case]:
    cases = []
    for command, args, option, values in table(COUNTS):
        setup = eval_run("run") if command == "report" else []
        for v in values.replace("ALL", "-1 0 1e9 1e12 2**70").split():
            cases.append(case(command, f"{option} {v}", f"{args} {option} {number(v)}", *setup))
    for command, args in table(WORKERS):
        for v in ("0", "1e6", "2**70"):
            cases.append(case(command, f"--workers {v}", f"{args} --workers {number(v)}"))
    for command, args in table(SEEDS):
        setup = [TASK_TINY] if command == "train task" else []
        for v in ("-1", "2**70"):
            cases.append(case(command, f"--seed {v}", f"{args} --seed {number(v)}", *setup))
    for v in ("0", "1", "13", "-1", "2**70"):
        cases.append(case("goals", f"--objects {v}", f"goals --objects {number(v)} --count 1"))
    for v in ("1", "13", "2**70"):
        args = f"demo --agent oracle --objects {number(v)} --out pics"
        cases.append(case("demo", f"--objects {v}", args))
    for command, args in table(MALFORMED):
        cases.append(case(command, f"malformed number: {args}", args))
    for command, args, values in table(SIZES):
        for v in shlex.split(values):
            cases.append(case(command, f"--sizes {v!r}", f"{args} --sizes {shlex.quote(v)}"))
    return cases


# scope | setting | raw JSON value (set in a tiny valid configuration)
CONFIG_VALUES = """
both   | lr          | "fast"
both   | lr          | -1
both   | lr          | NaN
both   | lr          | Infinity
both   | lr          | 0
both   | seed        | "abc"
both   | seed        | 2**70
both   | seed        | -1
both   | hidden      | 1e15
both   | hidden      | 0
both   | hidden      | -3
both   | hidden      | 1.5
both   | epochs      | 0
both   | epochs      | -1
both   | epochs      | "x"
both   | epochs      | 1e12
both   | epochs      | true
both   | batch_size  | 0
task   | copies      | 1e12
task   | copies      | -1
task   | reach       | "wizard"
task   | demos       | "missing/demos"
task   | demos       | "junk.bin"
task   | vary        | "yes"
motion | samples     | 0
motion | samples     | "x"
motion | threads     | 0
motion | threads     | 1e6
motion | loss        | "x"
motion | head        | "x"
motion | data        | "missing/data"
"""
CONFIG_FILES = [  # (name, setup of cfg.json; None: the tiny configuration in UTF-16)
    ("unknown setting", write_json("cfg.json", {"learning_rate": 0.1})),
    ("a JSON list", write("cfg.json", "[1, 2]\n")),
    ("an empty file", write("cfg.json", "")),
    ("truncated JSON", write("cfg.json", '{"epochs": 1')),
    ("deeply nested JSON", write("cfg.json", "[" * 100_000 + "]" * 100_000)),
    ("UTF-16 with BOM", None),
    ("Latin-1 bytes", write("cfg.json", b'{"seed": 0, "x": "' + LATIN1 + b'"}\n')),
    ("a directory", mkdir("cfg.json")),
    ("a FIFO", fifo("cfg.json")),
]


def config_cases() -> list[Case]:
    """Training configuration files with bad values, shapes and encodings."""
    cases = []
    for scope, tiny in (("task", TINY_TASK), ("motion", TINY_MOTION)):
        command = f"train {scope}"
        args = f"{command} --config cfg.json --out ck"
        for where, key, raw in table(CONFIG_VALUES):
            if where in ("both", scope):
                text = tiny_config(tiny, key, number(raw))
                junk = write("junk.bin", JUNK)
                cases.append(
                    case(command, f"config {key} {raw}", args, write("cfg.json", text), junk)
                )
        for name, setup in CONFIG_FILES:
            setup = setup or write("cfg.json", tiny_config(tiny).encode("utf-16"))
            cases.append(case(command, f"config {name}", args, setup))
        cases.append(case(command, "config missing", args))
    for option in ("--model wizard", "--model ''", "--primitive wizard"):
        args = base("train motion", f"--out ck {option}")
        cases.append(case("train motion", option, args, MOTION_TINY))
    return cases


GOAL_FILES = [  # (name, setup, size asked, also for eval-task)
    ("UTF-16 with BOM", [write("g.txt", GOALS_TEXT.encode("utf-16"))], 2, True),
    ("UTF-16-LE without BOM", [write("g.txt", GOALS_TEXT.encode("utf-16-le"))], 2, False),
    ("Latin-1 bytes", [write("g.txt", b"# " + LATIN1 + b"\n" + GOALS_TEXT.encode())], 2, True),
    ("UTF-8 BOM and Latin-1", [write("g.txt", b"\xef\xbb\xbf" + LATIN1 + b"\n")], 2, False),
    ("a directory", [mkdir("g.txt")], 2, True),
    ("a FIFO", [fifo("g.txt")], 2, True),
    ("no goal of the size asked", [write("g.txt", GOALS_TEXT)], 5, True),
    ("binary junk", [write("g.txt", JUNK)], 2, True),
    ("empty", [write("g.txt", "")], 2, False),
    ("comments only", [write("g.txt", "# nothing\n\n")], 2, False),
    ("missing", [], 2, True),
    ("malformed goal", [write("g.txt", "On(butter\n")], 2, False),
    ("unknown object", [write("g.txt", "On(wizard, shelf_a) & On(butter, shelf_b)\n")], 2, True),
]


def goal_file_cases() -> list[Case]:
    cases = []
    for name, setup, size, both in GOAL_FILES:
        for command in ("eval", "eval-task") if both else ("eval",):
            args = f"{command} --goals 1 --workers 1 --sizes {size} --goals-file g.txt --out run"
            cases.append(case(command, f"--goals-file {name}", args, *setup))
    return cases


def state_cases() -> list[Case]:
    """Odd existing state: directories where files belong, wrong JSON shapes, damage."""
    cases = []
    run = eval_run("run")
    for name, damage in [
        ("oracle/config.json a directory", dir_for("run/oracle/config.json")),
        ("oracle/episodes.jsonl a directory", dir_for("run/oracle/episodes.jsonl")),
        ("oracle/config.json a list", [write_json("run/oracle/config.json", [1, 2])]),
        ("oracle/config.json a number", [write_json("run/oracle/config.json", 42)]),
        ("oracle/config.json not UTF-8", [write("run/oracle/config.json", LATIN1)]),
        ("summary.json a directory", dir_for("run/summary.json")),
    ]:
        cases.append(case("eval", f"run folder {name}", base("eval", "--out run"), *run, *damage))

    folder_damage = {  # for commands whose --out folder is the run folder itself
        "config.json a directory": [mkdir("run/config.json")],
        "episodes.jsonl a directory": [
            write_json("run/config.json", {"kind": "x"}),
            mkdir("run/episodes.jsonl"),
        ],
        "config.json a list": [write_json("run/config.json", [1])],
        "config.json a number": [write_json("run/config.json", 42)],
        "config.json not UTF-8": [write("run/config.json", LATIN1)],
    }
    for command, names in [
        (
            "eval-task",
            [
                "config.json a directory",
                "episodes.jsonl a directory",
                "config.json a list",
                "config.json not UTF-8",
            ],
        ),
        ("eval-motion", ["config.json a directory", "config.json a number"]),
        ("bench timing", ["config.json a list"]),
        ("collect reach", ["config.json a directory", "config.json a list"]),
    ]:
        for name in names:
            args = base(command, "--out run")
            cases.append(case(command, f"run folder {name}", args, *folder_damage[name]))
    work = "run/work/place-seed0"
    for name, damage in [
        ("work/place-seed0/config.json a directory", mkdir(f"{work}/config.json")),
        ("work/place-seed0/config.json a list", write_json(f"{work}/config.json", [1])),
    ]:
        cases.append(
            case("collect place", f"dataset {name}", base("collect place", "--out run"), damage)
        )
    demos = copy_shipped("data/demos/v1", "run")
    for name, damage in [
        ("meta.json a directory", [mkdir("run/meta.json")]),
        ("meta.json a list", [write_json("run/meta.json", [1])]),
        ("demos.jsonl a directory", [demos, *dir_for("run/demos.jsonl")]),
    ]:
        cases.append(case("collect demos", f"dataset {name}", "collect demos --out run", *damage))

    ck = copy_shipped("checkpoints/task", "ck")
    task_damage = [  # a damaged copy of the shipped task planner
        ("preimage/config.json missing", [ck, remove("ck/preimage/config.json")]),
        ("preimage/model.safetensors truncated", [ck, truncate("ck/preimage/model.safetensors")]),
        ("preimage/config.json not UTF-8", [ck, write("ck/preimage/config.json", LATIN1)]),
        ("preimage/config.json a list", [ck, write_json("ck/preimage/config.json", [1])]),
        ("preimage/config.json a directory", [ck, *dir_for("ck/preimage/config.json")]),
        ("an empty folder", [mkdir("ck")]),
        ("a file", [write("ck", "x\n")]),
    ]
    for command, args, which in [
        ("eval-task", base("eval-task", "--out run"), task_damage),
        ("eval", base("eval", "--agent regression --out run"), task_damage[:4]),
        ("eval-reach", "eval-reach", task_damage[1:3]),
        ("bench task", "bench task --sizes 2 --goals 1", task_damage[1:2]),
    ]:
        for name, damage in which:
            cases.append(case(command, f"--checkpoint {name}", f"{args} --checkpoint ck", *damage))

    mk = copy_shipped("checkpoints/motion", "mk")
    push = copy_shipped("checkpoints/motion/push-gnn", "mk/place-gnn")
    motion_damage = [
        ("place-gnn/config.json missing", [mk, remove("mk/place-gnn/config.json")]),
        ("place-gnn/model.safetensors truncated", [mk, truncate("mk/place-gnn/model.safetensors")]),
        ("place-gnn/config.json not UTF-8", [mk, write("mk/place-gnn/config.json", LATIN1)]),
        ("place-gnn/config.json a list", [mk, write_json("mk/place-gnn/config.json", [1])]),
        ("place-gnn is a push network", [mk, remove("mk/place-gnn"), push]),
        ("place-gnn missing", [mk, remove("mk/place-gnn")]),
    ]
    for command, args, which in [
        (
            "eval",
            base("eval", "--agent paper --out run --motion-checkpoints mk"),
            motion_damage[:2] + motion_damage[4:],
        ),
        ("eval-motion", base("eval-motion", "--checkpoints mk"), motion_damage),
    ]:
        for name, damage in which:
            cases.append(case(command, f"motion checkpoints {name}", args, *damage))

    for name, setup in [
        ("missing", []),
        ("a file", [write("run", "x\n")]),
        ("an empty folder", [mkdir("run")]),
        ("summary.json not JSON", [write("run/summary.json", "{nope\n")]),
        ("summary.json a list", [write_json("run/summary.json", [1])]),
        ("summary.json an empty object", [write_json("run/summary.json", {})]),
        ("summary.json not UTF-8", [write("run/summary.json", LATIN1)]),
        ("summary.json a directory", [mkdir("run/summary.json")]),
        ("oracle/config.json a directory", [*run, *dir_for("run/oracle/config.json")]),
        ("a checkpoint folder", [copy_shipped("checkpoints/task", "run")]),
    ]:
        cases.append(case("report", f"RUN_DIR {name}", "report run", *setup))

    heldout = copy_shipped("data/reach/heldout", "tr")
    for name, setup in [
        ("missing", []),
        ("a file", [write("tr", "x\n")]),
        ("an empty folder", [mkdir("tr")]),
        ("episodes.jsonl a directory", [heldout, *dir_for("tr/episodes.jsonl")]),
        ("config.json not UTF-8", [heldout, write("tr/config.json", LATIN1)]),
        ("episodes.jsonl binary junk", [heldout, write("tr/episodes.jsonl", JUNK)]),
        ("a motion dataset", [copy_shipped("data/motion", "tr")]),
    ]:
        cases.append(case("eval-reach", f"--trials {name}", "eval-reach --trials tr", *setup))

    motion = copy_shipped("data/motion", "dd")
    for name, setup in [
        ("missing", []),
        ("a file", [write("dd", "x\n")]),
        ("an empty folder", [mkdir("dd")]),
        ("place.npz truncated", [motion, truncate("dd/place.npz")]),
        ("place.npz a directory", [motion, *dir_for("dd/place.npz")]),
        ("place.npz binary junk", [motion, write("dd/place.npz", JUNK)]),
        ("a reach collection", [copy_shipped("data/reach/v1", "dd")]),
    ]:
        args = base("train motion", "--out ck --data dd")
        cases.append(case("train motion", f"--data {name}", args, MOTION_TINY, *setup))
    return cases


# command | command line (the markup in it must come back verbatim) | echoed text
MARKUP = """
plan | plan --goal '[/]' | [/]
plan | plan --goal '[bold]x' | [bold]x
plan | plan --goal 'On([red]butter, shelf_a)' | On([red]butter, shelf_a)
plan | plan --goal 'On(butter, shelf_a)' --objects '[/]' | [/]
demo | demo --agent oracle --out pics --goal '[/]' | [/]
demo | demo --agent oracle --out pics --goal '[bold]x' | [bold]x
demo | demo --agent oracle --out pics --goal 'On([red]butter, shelf_a)' | On([red]butter, shelf_a)
eval | eval --goals 1 --workers 1 --sizes '[/]' | [/]
eval | eval --goals 1 --workers 1 --sizes 2 --motion '[/]' | [/]
eval-task | eval-task --sizes '[/]' | [/]
bench sim | bench sim --sizes '[bold]2' | [bold]2
eval | eval --goals 1 --workers 1 --sizes 2 --goals-file 'g[/]oals.txt' | g[/]oals.txt
eval-task | eval-task --sizes 2 --goals 1 --checkpoint 'ck[/]' | ck[/]
report | report 'run[/]' | run[/]
train task | train task --config 'c[/].json' --out ck | c[/].json
eval-reach | eval-reach --trials 't[/]' | t[/]
"""


def markup_cases() -> list[Case]:
    """Rich markup in input that an error message echoes: it must come back verbatim."""
    cases = [case(c, args.split(" ", 1)[1], args, echo=echo) for c, args, echo in table(MARKUP)]
    cases += [
        case(
            "eval",
            "--goals-file a directory '[red]x'",
            "eval --goals 1 --workers 1 --sizes 2 --goals-file '[red]x'",
            mkdir("[red]x"),
            echo="[red]x",
        ),
        case(
            "collect place",
            "--out a file '[bold]x'",
            base("collect place", "--out '[bold]x'"),
            write("[bold]x", "keep me\n"),
            echo="[bold]x",
        ),
    ]
    return cases


NAMES = """
eval           | eval --sizes 2 --goals 1 --workers 1 --out run --motion ''
eval           | eval --sizes 2 --goals 1 --workers 1 --out run --motion ,
eval           | eval --sizes 2 --goals 1 --workers 1 --out run --motion gnn,gnn
eval           | eval --sizes 2 --goals 1 --workers 1 --out run --motion wizard
eval           | eval --sizes 2 --goals 1 --workers 1 --out run --agent wizard
eval           | eval --sizes 2 --goals 1 --workers 1 --out run --planner ''
eval           | eval --sizes 2 --goals 1 --workers 1 --out run --perception ''
eval           | eval --sizes 2 --goals 1 --workers 1 --out run --perception rgb,,gt
eval           | eval --sizes 2 --goals 1 --workers 1 --out run --perception '[red]x'
eval           | eval --sizes 2 --goals 1 --out run --perception rgb --perception-checkpoint .
demo           | demo --perception ''
demo           | demo --perception rgb --perception-checkpoint .
eval-motion    | eval-motion --trials 1 --workers 1 --primitives ''
eval-motion    | eval-motion --trials 1 --workers 1 --primitives wizard
eval-motion    | eval-motion --trials 1 --workers 1 --primitives ,
eval-motion    | eval-motion --trials 1 --workers 1 --primitives place,place
bench collect  | bench collect --samples 1 --workers 1 --primitives ''
bench collect  | bench collect --samples 1 --workers 1 --primitives wizard
eval           | eval --sizes 2 --goals 1 --workers 1 --out run --ray ''
eval           | eval --sizes 2 --goals 1 --workers 1 --out run --ray 127.0.0.1:1
collect place  | collect place --samples 1 --workers 1 --out ds --ray ''
collect place  | collect place --samples 1 --workers 1 --out ds --ray 127.0.0.1:1
collect reach  | collect reach --states 1 --workers 1 --out ds --ray ''
collect reach  | collect reach --states 1 --workers 1 --out ds --ray 127.0.0.1:1
demo           | demo --out pics --agent wizard
demo           | demo --out pics --motion ''
eval-task      | eval-task --planner wizard
plan           | plan --goal 'On(butter, shelf_a)' --search wizard
plan           | plan --goal 'On(butter, shelf_a)' --objects wizard
plan           | plan --goal 'On(butter, shelf_a)' --objects ''
plan           | plan --goal 'On(butter, shelf_a)' --init garbage
plan           | plan --goal ''
plan           | plan --goal 'On(wizard, shelf_a)'
"""


def name_cases() -> list[Case]:
    cases = [case(c, args.split(" ", 1)[1][-60:], args) for c, args in table(NAMES)]
    thirteen = " & ".join(f"On(o{i}, shelf_a)" for i in range(13))
    cases.append(case("plan", "--goal of 13 objects", ["plan", "--goal", thirteen]))
    huge = " & ".join([GOAL2] * 2000)  # 4000 literals, under the kernel's 128 KiB per argument
    cases.append(case("plan", "--goal of 4000 literals", ["plan", "--goal", huge]))
    return cases


def cross_cases() -> list[Case]:
    """One command's folder given as another's output or input."""
    ck = copy_shipped("checkpoints/task", "ck")
    mk = copy_shipped("checkpoints/motion", "mk")
    pg = copy_shipped("checkpoints/motion/place-gnn", "pg")
    cases = [
        case("eval", "--out a task checkpoint", base("eval", "--out ck"), ck),
        case("eval-task", "--out a task checkpoint", base("eval-task", "--out ck"), ck),
        case("eval-motion", "--out the motion checkpoints", base("eval-motion", "--out mk"), mk),
        case(
            "bench timing",
            "--out a demos dataset",
            base("bench timing", "--out dd"),
            copy_shipped("data/demos/v1", "dd"),
        ),
        case(
            "train task",
            "--out an eval run folder",
            base("train task", "--out run"),
            TASK_TINY,
            *eval_run("run"),
        ),
        case(
            "train motion",
            "--out a task checkpoint",
            base("train motion", "--out ck"),
            MOTION_TINY,
            ck,
        ),
        case(
            "eval-task",
            "--checkpoint a motion checkpoint",
            base("eval-task", "--out run --checkpoint pg"),
            pg,
        ),
        case("eval-reach", "--checkpoint a motion checkpoint", "eval-reach --checkpoint pg", pg),
        case(
            "eval",
            "--checkpoint the motion checkpoints",
            base("eval", "--agent regression --checkpoint mk --out run"),
            mk,
        ),
        case(
            "eval",
            "--motion-checkpoints a task checkpoint",
            base("eval", "--agent paper --motion-checkpoints ck --out run"),
            ck,
        ),
        case(
            "eval-motion",
            "--checkpoints a task checkpoint",
            base("eval-motion", "--checkpoints ck"),
            ck,
        ),
    ]
    for command in ("collect place", "collect push", "collect reach", "collect demos"):
        args = base(command, "--out run")
        cases.append(case(command, "--out an eval run folder", args, *eval_run("run")))
    return cases


def data_loss_cases() -> list[Case]:
    """Defaults that would overwrite the shipped data (a copy in the cwd, HSGPLAN_HOME there)."""
    home = own_home()
    return [
        case(
            "collect place",
            "default --out over the shipped dataset (--samples 60)",
            "collect place --samples 60 --workers 1",
            *home,
            own_home=True,
            keep=SHIPPED,
        ),
        case(
            "collect push",
            "default --out over the shipped dataset (--samples 60)",
            "collect push --samples 60 --workers 1",
            *home,
            own_home=True,
            keep=SHIPPED,
        ),
        case(
            "collect demos",
            "default --out over the shipped demos (--seed 1)",
            "collect demos --seed 1",
            *home,
            own_home=True,
            keep=SHIPPED,
        ),
        case(
            "collect reach",
            "default --out over the shipped collection (--seed 1)",
            "collect reach --states 1 --workers 1 --seed 1",
            *home,
            own_home=True,
            keep=SHIPPED,
        ),
        case(
            "train task",
            "default --out over the shipped checkpoint",
            base("train task"),
            *home,
            TASK_TINY,
            own_home=True,
            keep=SHIPPED,
        ),
        case(
            "train motion",
            "default --out over the shipped place-gnn",
            base("train motion"),
            *home,
            MOTION_TINY,
            own_home=True,
            keep=SHIPPED,
        ),
        case(
            "train motion",
            "default --out over the shipped push-mlp",
            base("train motion", "--primitive push --model mlp"),
            *home,
            MOTION_TINY,
            own_home=True,
            keep=SHIPPED,
        ),
    ]


def all_cases() -> list[Case]:
    cases = (
        output_cases()
        + number_cases()
        + config_cases()
        + goal_file_cases()
        + state_cases()
        + markup_cases()
        + name_cases()
        + cross_cases()
        + data_loss_cases()
    )
    seen: dict[str, int] = {}
    for c in cases:  # ids unique: a repeated name gets a counter
        seen[c.id] = seen.get(c.id, 0) + 1
        if seen[c.id] > 1:
            c.name += f" #{seen[c.id]}"
    return cases


# ---------------------------------------------------------------------------------------------
# Runner
# ---------------------------------------------------------------------------------------------


@dataclass
class Result:
    case: Case
    kind: str
    gist: str
    code: int | None
    seconds: float
    stdout: str
    stderr: str
    touched: list[str]
    notes: list[str]


def snapshot(root: Path) -> dict[str, str]:
    """Every entry under `root`: a file by its content hash, a folder, a link, anything else
    (a FIFO is never opened)."""
    entries = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for name in dirnames + filenames:
            p = Path(dirpath) / name
            rel = str(p.relative_to(root))
            st = os.lstat(p)
            if stat.S_ISLNK(st.st_mode):
                entries[rel] = "link:" + os.readlink(p)
            elif stat.S_ISDIR(st.st_mode):
                entries[rel] = "dir"
            elif stat.S_ISREG(st.st_mode):
                h = hashlib.sha256()
                with open(p, "rb") as f:
                    for block in iter(lambda f=f: f.read(1 << 20), b""):
                        h.update(block)
                entries[rel] = h.hexdigest()
            else:
                entries[rel] = f"special:{stat.S_IFMT(st.st_mode)}"
    return entries


def quick_snapshot(root: Path) -> dict[str, tuple]:
    """Names, sizes and modification times: cheap enough to take around every case."""
    out = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for name in dirnames + filenames:
            p = Path(dirpath) / name
            st = os.lstat(p)
            out[str(p.relative_to(root))] = (st.st_mode, st.st_size, st.st_mtime_ns)
    return out


def diff(before: dict, after: dict) -> list[str]:
    changes = [f"created {k}" for k in sorted(after.keys() - before.keys())]
    changes += [f"removed {k}" for k in sorted(before.keys() - after.keys())]
    changes += [
        f"changed {k}" for k in sorted(before.keys() & after.keys()) if before[k] != after[k]
    ]
    return changes


def child_env(home: Path) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONHASHSEED", "COLUMNS", "LINES")}
    env["HSGPLAN_HOME"] = str(home)
    return env


def tail(path: Path, limit: int = 65536) -> str:
    with open(path, "rb") as f:
        f.seek(max(0, path.stat().st_size - limit))
        return f.read().decode("utf-8", "replace")


def group_alive(pgid: int) -> bool:
    try:
        os.killpg(pgid, 0)
    except (ProcessLookupError, PermissionError):
        return False
    return True


def kill_group(pgid: int) -> None:
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.killpg(pgid, signal.SIGKILL)


def run_case(
    case: Case, root: Path, home: Path, timeout: float, mem_gb: float, keep: bool
) -> Result:
    """One case, never raising: a failure of the harness itself is reported as "other"."""
    try:
        return _run_case(case, root, home, timeout, mem_gb, keep)
    except Exception as e:  # one broken case must not end the run
        gist = f"the harness could not run it: {type(e).__name__}: {e}"
        return Result(case, "other", gist, None, 0.0, "", "", [], [])


def _run_case(
    case: Case, root: Path, home: Path, timeout: float, mem_gb: float, keep: bool
) -> Result:
    work = Path(tempfile.mkdtemp(prefix="case-", dir=root))
    cwd = work / "cwd"
    cwd.mkdir()
    for step in case.setup:
        step(cwd, home)
    before = snapshot(cwd)
    home_before = quick_snapshot(home)
    # sh sets the memory limit and closes stdin, then becomes hsgplan (same pid, own group)
    script = f'ulimit -v {int(mem_gb * 1024 * 1024)}; exec "$@" 0<&-'
    argv = ["/bin/sh", "-c", script, "sh", str(HSGPLAN), *case.args]
    notes = []
    start = time.monotonic()
    with open(work / "stdout", "wb") as out, open(work / "stderr", "wb") as err:
        proc = subprocess.Popen(
            argv,
            cwd=cwd,
            env=child_env(cwd if case.own_home else home),
            stdin=subprocess.DEVNULL,
            stdout=out,
            stderr=err,
            start_new_session=True,
        )
        try:
            code: int | None = proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            kill_group(proc.pid)
            proc.wait()
            code = None
    seconds = time.monotonic() - start
    if code is not None:
        deadline = time.monotonic() + 2.0  # workers shutting down are given a moment
        while group_alive(proc.pid) and time.monotonic() < deadline:
            time.sleep(0.1)
        if group_alive(proc.pid):
            notes.append("left processes running after it exited (killed)")
            kill_group(proc.pid)
    stdout, stderr = tail(work / "stdout"), tail(work / "stderr")
    touched = diff(before, snapshot(cwd))
    home_changes = diff(home_before, quick_snapshot(home))
    if home_changes:
        touched += [f"HSGPLAN_HOME: {c}" for c in home_changes]
        notes.append("the shared HSGPLAN_HOME changed while it ran (maybe by a case beside it)")
    if case.keep:
        elsewhere = [
            t
            for t in touched
            if not t.startswith("HSGPLAN_HOME") and not _under(t.split(" ", 1)[1], case.keep)
        ]
        touched = [t for t in touched if t not in elsewhere]
        if elsewhere:
            notes.append("wrote outside the kept folders: " + "; ".join(elsewhere[:3]))
    kind, gist = classify(case, code, stdout, stderr, touched, timeout)
    if kind != "accepted" and touched:
        notes.append("also touched files: " + "; ".join(touched[:3]))
    if not keep:
        shutil.rmtree(work, ignore_errors=True)
    return Result(case, kind, gist, code, seconds, stdout, stderr, touched, notes)


def _under(path: str, folders: tuple[str, ...]) -> bool:
    return any(path == f or path.startswith(f + "/") for f in folders)


def classify(case: Case, code, stdout: str, stderr: str, touched, timeout) -> tuple[str, str]:
    lines = [line for line in stderr.splitlines() if line.strip()]
    last = lines[-1].strip() if lines else ""
    if code is None:
        return "hang", f"still running after {timeout:g} s" + (f"; stderr: {last}" if last else "")
    if "Traceback" in stderr or "Traceback" in stdout:
        return "traceback", _exception_line(stderr + "\n" + stdout) or last
    if code == 1 and (exc := _exception_line(stderr)):
        return "traceback", exc
    if code == 0 and case.keep and not touched:
        return "refused", f"exit 0 and {', '.join(case.keep)} unchanged (counted as clean)"
    if touched or code == 0:
        what = "; ".join(touched[:4]) + (
            f"; ... {len(touched) - 4} more" if len(touched) > 4 else ""
        )
        return "accepted", f"exit {code}" + (f"; {what}" if what else "")
    if any(line.lstrip().startswith(("Usage:", "╭", "│", "Try '")) for line in lines):
        return "usage-box", f"exit {code}; {len(lines)} stderr lines; {last}"
    if code == 2 and len(lines) == 1 and lines[0].startswith("error:"):
        if case.echo is not None and case.echo not in lines[0]:
            return "other", f"error line does not quote {case.echo!r} verbatim: {lines[0]}"
        return "refused", lines[0]
    first = lines[0].strip() if lines else "(no stderr)"
    more = f" ... {last}" if len(lines) > 1 else ""
    return "other", f"exit {code}; {len(lines)} stderr lines: {first}{more}"


EXCEPTION = re.compile(r"^\s*([A-Za-z_][\w.]*(Error|Exception|Warning|Exit|Interrupt))\b.*")


def _exception_line(text: str) -> str:
    found = [m.group(0).strip() for m in map(EXCEPTION.match, text.splitlines()) if m]
    return found[-1] if found else ""


def run_all(cases: list[Case], jobs: int, timeout: float, mem_gb: float, keep: bool) -> list:
    root = Path(tempfile.mkdtemp(prefix="hsgplan-hostile-"))
    home = root / "home"
    for name in SHIPPED:
        shutil.copytree(REPO / name, home / name, symlinks=True)
    home_at_start = snapshot(home)
    results: list[Result] = []
    lock = threading.Lock()
    try:
        with ThreadPoolExecutor(max_workers=jobs) as pool:
            futures = [pool.submit(run_case, c, root, home, timeout, mem_gb, keep) for c in cases]
            for future in as_completed(futures):
                r = future.result()
                with lock:
                    results.append(r)
                    print(
                        f"[{len(results)}/{len(cases)}] {r.kind:<9} {r.seconds:5.1f}s {r.case.id}",
                        file=sys.stderr,
                        flush=True,
                    )
        home_changes = diff(home_at_start, snapshot(home))
        if home_changes:
            print(
                "WARNING: the shared HSGPLAN_HOME copy changed during the run: "
                + "; ".join(home_changes[:10]),
                file=sys.stderr,
            )
    finally:
        if keep:
            print(f"kept {root}", file=sys.stderr)
        else:
            shutil.rmtree(root, ignore_errors=True)
    order = {c.id: i for i, c in enumerate(cases)}
    return sorted(results, key=lambda r: order[r.case.id])


# ---------------------------------------------------------------------------------------------
# Reporter
# ---------------------------------------------------------------------------------------------


def counts_by_command(results: list[Result]) -> dict[str, dict[str, int]]:
    table = {}
    for command in [*COMMANDS, *sorted({r.case.command for r in results} - set(COMMANDS))]:
        rows = [r for r in results if r.case.command == command]
        if rows:
            table[command] = {"cases": len(rows)} | {
                k: sum(r.kind == k for r in rows) for k in KINDS
            }
    return table


def totals(table: dict[str, dict[str, int]]) -> dict[str, int]:
    return {k: sum(row[k] for row in table.values()) for k in ("cases", *KINDS)}


def markdown(results: list[Result]) -> str:
    table = counts_by_command(results)
    header = ("command", "cases", *KINDS)
    lines = ["| " + " | ".join(header) + " |", "|---|" + "---:|" * (len(header) - 1)]
    for command, row in [*table.items(), ("**total**", totals(table))]:
        lines.append("| " + " | ".join([command, *(str(row[k]) for k in header[1:])]) + " |")
    return "\n".join(lines)


def first_last(text: str) -> tuple[str, str]:
    lines = [line.rstrip() for line in text.splitlines() if line.strip()]
    return (lines[0], lines[-1]) if lines else ("", "")


def failure_json(r: Result) -> dict:
    first, last = first_last(r.stderr)
    return {
        "id": r.case.id,
        "command": r.case.command,
        "argv": ["hsgplan", *r.case.args],
        "kind": r.kind,
        "gist": r.gist,
        "exit_code": r.code,
        "seconds": round(r.seconds, 1),
        "stderr_first": first,
        "stderr_last": last,
        "touched": r.touched[:20],
        "notes": r.notes,
    }


def shell_line(args: list[str]) -> str:
    text = " ".join(shlex.quote(a) for a in ["hsgplan", *args])
    return text if len(text) <= 300 else text[:300] + f"... ({len(text)} characters)"


def print_failures(results: list[Result]) -> None:
    failing = [r for r in results if r.kind != "refused"]
    for kind in KINDS[1:]:
        group = [r for r in failing if r.kind == kind]
        if not group:
            continue
        print(f"\n## {kind} ({len(group)})\n")
        for r in group:
            first, last = first_last(r.stderr)
            print(f"- {r.case.id}\n  $ {shell_line(r.case.args)}\n  gist: {r.gist[:300]}")
            print(f"  exit {r.code}, {r.seconds:.1f} s")
            if first:
                print(f"  stderr first: {first[:200]}")
            if last and last != first:
                print(f"  stderr last:  {last[:200]}")
            for note in r.notes:
                print(f"  note: {note[:300]}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", type=int, default=2, help="cases run side by side")
    parser.add_argument("--timeout", type=float, default=20.0, help="seconds before a hang")
    parser.add_argument("--only", help="run only cases whose id or argv holds this text")
    parser.add_argument("--list", action="store_true", help="list the cases and run nothing")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--failures", action="store_true", help="print every non-clean case")
    parser.add_argument("--mem-gb", type=float, default=4.0, help="ulimit -v of each case")
    parser.add_argument("--keep", action="store_true", help="keep the scratch folders")
    args = parser.parse_args(argv)
    if not HSGPLAN.exists():
        parser.error(f"{HSGPLAN} does not exist (make the venv first)")

    cases = all_cases()
    if args.only:
        cases = [c for c in cases if args.only in c.id or args.only in " ".join(c.args)]
    if args.list:
        for c in cases:
            print(f"{c.id}\n    $ {shell_line(c.args)}")
        print(f"{len(cases)} cases")
        return 0
    if not cases:
        parser.error("no case matches --only")

    results = run_all(cases, max(1, args.jobs), args.timeout, args.mem_gb, args.keep)
    clean = all(r.kind == "refused" for r in results)
    if args.json:
        table = counts_by_command(results)
        report = {
            "counts": table,
            "totals": totals(table),
            "failures": [failure_json(r) for r in results if r.kind != "refused"],
        }
        print(json.dumps(report, indent=2))
        return 0 if clean else 1
    print(markdown(results))
    if args.failures:
        print_failures(results)
    return 0 if clean else 1


if __name__ == "__main__":
    try:
        sys.exit(main())
    except BrokenPipeError:  # `| head`
        sys.stderr.close()
