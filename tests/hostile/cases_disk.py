"""Hostile files and disks: inputs too large to read, loops of links, a disk that fills up,
motion datasets damaged or swapped, training configurations that contradict the command, and
training progress that is not ours."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from tests.hostile.case import (
    GOAL2,
    MOTION_TINY,
    TINY_MOTION,
    Case,
    Setup,
    base,
    case,
    copy_shipped,
    mkdir,
    remove,
    symlink,
    tiny_config,
    write,
)

LOOP = [symlink("loop", "loop2"), symlink("loop2", "loop")]
SMALL_GOAL = "On(butter, shelf_a) & On(popcorn, shelf_b)"
LONG_GOAL = " & ".join([GOAL2] * 20)  # a valid goal of about 1,000 characters


def _goal_lines(rel: str, count: int, line: str) -> Setup:
    return write(rel, (line + "\n") * count)


def _edited(rel: str, edit) -> Setup:
    """The shipped `place.npz` (from the home copy) with `edit` applied to its arrays, at
    `rel`; no manifest beside it, so only the rows' own checks can find the damage."""

    def step(cwd: Path, home: Path) -> None:
        with np.load(home / "data" / "motion" / "place.npz") as z:
            arrays = {k: z[k] for k in z.files}
        edit(arrays)
        (cwd / rel).parent.mkdir(parents=True, exist_ok=True)
        with open(cwd / rel, "wb") as f:
            np.savez(f, **arrays)

    return step


def _out_of_range(arrays: dict) -> None:
    arrays["obj"] = arrays["obj"].copy()
    arrays["obj"][7] = 42


def _swapped(arrays: dict) -> None:
    arrays["obj"], arrays["target"] = arrays["target"], arrays["obj"]


def _bins_too_far(arrays: dict) -> None:
    arrays["bins"] = arrays["bins"].copy()
    arrays["bins"][3, 1] = 10


def _infinite_pose(arrays: dict) -> None:
    arrays["poses"] = arrays["poses"].copy()
    arrays["poses"][5, 0, 2] = np.inf


def _manifest(rel: str, **changes) -> Setup:
    """The shipped `place.json` (its checksum still right) with `changes`, at `rel`."""

    def step(cwd: Path, home: Path) -> None:
        manifest = json.loads((home / "data" / "motion" / "place.json").read_text())
        (cwd / rel).write_text(json.dumps(manifest | changes))

    return step


def _motion_progress(rel: str, payload: bytes | None, name: str | None = None) -> list[Setup]:
    """A checkpoint folder in training with the tiny motion configuration, whose progress file
    (`name`, by default today's) is `payload` (None: a torch pickle)."""
    from dataclasses import asdict

    from hsgplan.motion.train import MotionTrainConfig
    from hsgplan.training import PROGRESS, TRAIN_CONFIG

    config = asdict(MotionTrainConfig.from_json(TINY_MOTION | {"primitive": "place"}))

    def progress(cwd: Path, home: Path) -> None:
        path = cwd / rel / (name or PROGRESS)
        if payload is None:
            import torch

            torch.save({"model": {"w": torch.zeros(2)}, "epoch": 1}, path)
        else:
            path.write_bytes(payload)

    return [write(f"{rel}/{TRAIN_CONFIG}", json.dumps(config, indent=2) + "\n"), progress]


def disk_cases() -> list[Case]:
    big = "eval world --sizes 2 --goals 1 --workers 1 --goals-file g.txt --out run"
    task = "eval task --sizes 2 --goals 1 --workers 1 --goals-file g.txt --out run"
    cases = [
        case("eval", "--goals-file of 40 MiB", big, _goal_lines("g.txt", 40_000, LONG_GOAL)),
        case("eval", "--goals-file of 100,001 goals", big, _goal_lines("g.txt", 100_001, GOAL2)),
        case(
            "eval task", "--goals-file of 100,001 goals", task, _goal_lines("g.txt", 100_001, GOAL2)
        ),
        case("eval", "--goals-file a loop of links", big.replace("g.txt", "loop"), *LOOP),
        case(
            "eval",
            "--checkpoint a loop of links",
            base("eval", "--agent regression --checkpoint loop --out run"),
            *LOOP,
        ),
        case(
            "eval task",
            "--checkpoint a loop of links",
            base("eval task", "--checkpoint loop --out run"),
            *LOOP,
        ),
        case(
            "train motion", "--config a loop of links", "train motion --config loop --out ck", *LOOP
        ),
        case("report", "RUN_DIR a loop of links", "report loop", *LOOP),
        case(
            "goals",
            "--out over a file, disk full",
            "goals --objects 6 --goals 500 --out g.txt",
            write("g.txt", f"{SMALL_GOAL}\n"),
            file_bytes=4096,
        ),
    ]
    data = base("train motion", "--out ck --data dd")
    for name, damage in [
        ("an object index out of range", _out_of_range),
        ("objects and targets swapped", _swapped),
        ("a bin out of range", _bins_too_far),
        ("an infinite pose", _infinite_pose),
    ]:
        cases.append(
            case(
                "train motion",
                f"--data place.npz with {name}",
                data,
                MOTION_TINY,
                _edited("dd/place.npz", damage),
            )
        )
    motion = copy_shipped("data/motion", "dd")
    swap = [motion, remove("dd/place.npz"), copy_shipped("data/motion/push.npz", "dd/place.npz")]
    cases += [
        case("train motion", "--data push trials as place.npz", data, MOTION_TINY, *swap),
        case(
            "train motion",
            "--data push trials as place.npz, no manifest",
            data,
            MOTION_TINY,
            *swap,
            remove("dd/place.json"),
        ),
        case(
            "train motion",
            "--data a manifest of another primitive",
            data,
            MOTION_TINY,
            motion,
            _manifest("dd/place.json", primitive="push"),
        ),
        case(
            "train motion",
            "--data a manifest of other samples",
            data,
            MOTION_TINY,
            motion,
            _manifest("dd/place.json", samples=100),
        ),
        case(
            "train motion",
            "config primitive pick",
            "train motion --config cfg.json --out ck",
            write("cfg.json", tiny_config(TINY_MOTION, "primitive", '"pick"')),
        ),
        case(
            "train motion",
            "config primitive push, --primitive place",
            "train motion --config cfg.json --primitive place --out ck",
            write("cfg.json", tiny_config(TINY_MOTION, "primitive", '"push"')),
        ),
        case(
            "train motion",
            "config model mlp, --model gnn",
            "train motion --config cfg.json --model gnn --out ck",
            write("cfg.json", tiny_config(TINY_MOTION, "model", '"mlp"')),
        ),
        case(
            "train motion",
            "config samples beyond the data",
            "train motion --config cfg.json --out ck",
            write("cfg.json", tiny_config(TINY_MOTION, "samples", "20000")),
        ),
        case(
            "train motion",
            "progress a torch pickle",
            base("train motion", "--out ck"),
            MOTION_TINY,
            mkdir("ck"),
            *_motion_progress("ck", None),
        ),
        case(
            "train motion",
            "progress.pt of an older version (a pickle)",
            base("train motion", "--out ck"),
            MOTION_TINY,
            mkdir("ck"),
            *_motion_progress("ck", None, "progress.pt"),
        ),
        case(
            "train motion",
            "progress binary junk",
            base("train motion", "--out ck"),
            MOTION_TINY,
            mkdir("ck"),
            *_motion_progress("ck", b"\x00" * 64),
        ),
    ]
    return cases
