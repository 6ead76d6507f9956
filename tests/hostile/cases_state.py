"""Hostile state: damaged run folders, checkpoints and datasets, one command's folder given
to another, and defaults that would overwrite the shipped data."""

from __future__ import annotations

from tests.hostile.case import (
    JUNK,
    LATIN1,
    MOTION_TINY,
    SHIPPED,
    TASK_TINY,
    Case,
    base,
    case,
    copy_shipped,
    dir_for,
    eval_run,
    mkdir,
    own_home,
    remove,
    truncate,
    write,
    write_json,
)


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
            "eval task",
            [
                "config.json a directory",
                "episodes.jsonl a directory",
                "config.json a list",
                "config.json not UTF-8",
            ],
        ),
        ("eval motion", ["config.json a directory", "config.json a number"]),
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
        ("eval task", base("eval task", "--out run"), task_damage),
        ("eval", base("eval", "--agent regression --out run"), task_damage[:4]),
        ("eval reach", "eval reach", task_damage[1:3]),
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
            base("eval", "--agent learned --out run --motion-checkpoints mk"),
            motion_damage[:2] + motion_damage[4:],
        ),
        ("eval motion", base("eval motion", "--motion-checkpoints mk"), motion_damage),
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
        cases.append(case("eval reach", f"--trials {name}", "eval reach --data tr", *setup))

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


def cross_cases() -> list[Case]:
    """One command's folder given as another's output or input."""
    ck = copy_shipped("checkpoints/task", "ck")
    mk = copy_shipped("checkpoints/motion", "mk")
    pg = copy_shipped("checkpoints/motion/place-gnn", "pg")
    cases = [
        case("eval", "--out a task checkpoint", base("eval", "--out ck"), ck),
        case("eval task", "--out a task checkpoint", base("eval task", "--out ck"), ck),
        case("eval motion", "--out the motion checkpoints", base("eval motion", "--out mk"), mk),
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
            "eval task",
            "--checkpoint a motion checkpoint",
            base("eval task", "--out run --checkpoint pg"),
            pg,
        ),
        case("eval reach", "--checkpoint a motion checkpoint", "eval reach --checkpoint pg", pg),
        case(
            "eval",
            "--checkpoint the motion checkpoints",
            base("eval", "--agent regression --checkpoint mk --out run"),
            mk,
        ),
        case(
            "eval",
            "--motion-checkpoints a task checkpoint",
            base("eval", "--agent learned --motion-checkpoints ck --out run"),
            ck,
        ),
        case(
            "eval motion",
            "--motion-checkpoints a task checkpoint",
            base("eval motion", "--motion-checkpoints ck"),
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
            "default --out over the shipped dataset (--samples 4)",
            "collect place --samples 4 --workers 1 --tasks-per-chunk 4",
            *home,
            own_home=True,
            keep=SHIPPED,
        ),
        case(
            "collect push",
            "default --out over the shipped dataset (--samples 4)",
            "collect push --samples 4 --workers 1 --tasks-per-chunk 4",
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
