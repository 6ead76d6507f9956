"""Hostile input given on the command line or in files it names: output paths, counts,
configurations, goal files, Rich markup and names."""

from __future__ import annotations

import shlex

from tests.hostile.case import (
    BASE,
    GOAL2,
    GOALS_TEXT,
    JUNK,
    KEEP,
    LATIN1,
    MOTION_TINY,
    TASK_TINY,
    TINY_MOTION,
    TINY_TASK,
    Case,
    base,
    case,
    eval_run,
    fifo,
    mkdir,
    number,
    symlink,
    table,
    tiny_config,
    write,
    write_json,
)


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
            ("a loop of links", "loop", [symlink("loop", "loop2"), symlink("loop2", "loop")]),
        ]
        # (a goal file under a missing folder is fine: its folders are made)
        for label, path, more in bad:
            if command == "goals" and label == "an existing file":
                continue  # its --out is a file: one that exists is replaced (tests/test_cli.py)
            cases.append(case(command, f"--out {label}", f"{args} --out {path}", *setup, *more))
    return cases


# command | base command line | option | values (ALL: -1 0 1e9 1e12 2**70)
COUNTS = """
goals          | goals --objects 2                                    | --goals     | ALL
eval           | eval world --sizes 2 --workers 1                           | --goals     | ALL
eval           | eval world --sizes 2 --goals 1 --workers 1                 | --repeats   | 0
eval task      | eval task --sizes 2 --workers 1                      | --goals     | -1 2**70
collect place  | collect place --workers 1 --out ds                   | --samples   | ALL
collect push   | collect push --workers 1 --out ds                    | --samples   | -1 1e12
collect place  | collect place --samples 1 --workers 1 --out ds       | --tasks-per-chunk | 0
collect reach  | collect reach --workers 1 --out ds                   | --states    | ALL
eval motion    | eval motion --workers 1 --primitives place           | --trials    | ALL
bench sim      | bench sim --sizes 2                                  | --episodes  | -1 1e12
bench symbolic | bench symbolic --sizes 2                             | --goals     | -1 1e12
bench symbolic | bench symbolic --sizes 2 --goals 1                   | --optimal-max-size | -1
bench task     | bench task --sizes 2                                 | --goals     | -1 1e12
bench timing   | bench timing --sizes 2 --workers 1                   | --goals     | -1 1e12
bench collect  | bench collect --workers 1 --primitives place         | --samples   | -1 1e12
report         | report run                                           | --failures  | -1
collect images | collect images --workers 1 --out ds                  | --samples   | ALL
eval perception | eval perception                                     | --scenes    | ALL
bench observe  | bench observe                                        | --scenes    | -1 0 1e12
bench push-reach | bench push-reach                                   | --tasks     | -1 1e12
bench push-reach | bench push-reach --tasks 1                         | --first     | -1 2**70
bench line-error | bench line-error                                   | --tasks     | -1 1e12
bench push-settings | bench push-settings                             | --trials    | -1 1e12
scenes         | scenes --out sc                                      | --layouts   | ALL
"""
# a small count each: a huge pool for one item would still start one process
WORKERS = """
eval           | eval world --sizes 2 --goals 1
eval task      | eval task --sizes 2 --goals 1
eval motion    | eval motion --trials 1 --primitives place
collect place  | collect place --samples 1 --out ds
collect push   | collect push --samples 1 --out ds
collect reach  | collect reach --states 1 --out ds
collect images | collect images --samples 1 --out ds
"""
SEEDS = """
goals          | goals --objects 2 --goals 1
demo           | demo --agent oracle --objects 2 --out pics
eval           | eval world --sizes 2 --goals 1 --workers 1
eval task      | eval task --sizes 2 --goals 1 --workers 1
collect demos  | collect demos --out ds
collect place  | collect place --samples 1 --workers 1 --out ds
collect reach  | collect reach --states 1 --workers 1 --out ds
train task     | train task --config tiny.json --out ck
collect images | collect images --samples 1 --workers 1 --out ds
eval perception | eval perception --scenes 1
scenes         | scenes --layouts 1 --out sc
"""
MALFORMED = """
goals          | goals --objects 2 --goals abc
goals          | goals --objects 2 --goals 1.5
goals          | goals --objects 2 --goals ''
eval           | eval world --sizes 2 --goals 1 --workers 1e3
collect place  | collect place --samples 0x10 --out ds
bench timing   | bench timing --sizes 2 --goals 1 --workers 1 --search pddl
"""
# command | base command line | --sizes values (a space-separated list; '' is the empty value)
SIZES = """
eval           | eval world --goals 1 --workers 1                 | '' 6-2 0 13 2-1000000000
eval task      | eval task --goals 1 --workers 1            | '' 6-2 13 2-1000000000
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
        cases.append(case("goals", f"--objects {v}", f"goals --objects {number(v)} --goals 1"))
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


GOAL_FILES = [  # (name, setup, size asked, also for eval task)
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
        for command in ("eval", "eval task") if both else ("eval",):
            args = f"{command} --goals 1 --workers 1 --sizes {size} --goals-file g.txt --out run"
            cases.append(case(command, f"--goals-file {name}", args, *setup))
    return cases


# command | command line (the markup in it must come back verbatim) | echoed text
MARKUP = """
plan | plan --goal '[/]' | [/]
plan | plan --goal '[bold]x' | [bold]x
plan | plan --goal 'On([red]butter, shelf_a)' | On([red]butter, shelf_a)
plan | plan --goal 'On(butter, shelf_a)' --names '[/]' | [/]
demo | demo --agent oracle --out pics --goal '[/]' | [/]
demo | demo --agent oracle --out pics --goal '[bold]x' | [bold]x
demo | demo --agent oracle --out pics --goal 'On([red]butter, shelf_a)' | On([red]butter, shelf_a)
eval | eval world --goals 1 --workers 1 --sizes '[/]' | [/]
eval | eval world --goals 1 --workers 1 --sizes 2 --motion '[/]' | [/]
eval task | eval task --sizes '[/]' | [/]
bench sim | bench sim --sizes '[bold]2' | [bold]2
eval | eval world --goals 1 --workers 1 --sizes 2 --goals-file 'g[/]oals.txt' | g[/]oals.txt
eval task | eval task --sizes 2 --goals 1 --checkpoint 'ck[/]' | ck[/]
report | report 'run[/]' | run[/]
train task | train task --config 'c[/].json' --out ck | c[/].json
eval reach | eval reach --data 't[/]' | t[/]
plan | plan --goal 'On(butter, shelf_a)' --scene 's[/].toml' | s[/].toml
eval task | eval task --sizes 2 --goals 1 --scene 's[/]' | s[/]
"""


def markup_cases() -> list[Case]:
    """Rich markup in input that an error message echoes: it must come back verbatim."""
    cases = [case(c, args.split(" ", 1)[1], args, echo=echo) for c, args, echo in table(MARKUP)]
    cases += [
        case(
            "eval",
            "--goals-file a directory '[red]x'",
            "eval world --goals 1 --workers 1 --sizes 2 --goals-file '[red]x'",
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
eval           | eval world --sizes 2 --goals 1 --workers 1 --out run --motion ''
eval           | eval world --sizes 2 --goals 1 --workers 1 --out run --motion ,
eval           | eval world --sizes 2 --goals 1 --workers 1 --out run --motion gnn,gnn
eval           | eval world --sizes 2 --goals 1 --workers 1 --out run --motion wizard
eval           | eval world --sizes 2 --goals 1 --workers 1 --out run --agent wizard
eval           | eval world --sizes 2 --goals 1 --workers 1 --out run --planner ''
eval           | eval world --sizes 2 --goals 1 --workers 1 --out run --perception ''
eval           | eval world --sizes 2 --goals 1 --workers 1 --out run --perception rgb,,gt
eval           | eval world --sizes 2 --goals 1 --workers 1 --out run --perception '[red]x'
eval           | eval world --sizes 2 --goals 1 --out run --perception rgb --perception-checkpoint .
demo           | demo --perception ''
bench observe  | bench observe --scenes 1 --perception-checkpoint .
demo           | demo --perception rgb --perception-checkpoint .
eval motion    | eval motion --trials 1 --workers 1 --primitives ''
eval motion    | eval motion --trials 1 --workers 1 --primitives wizard
eval motion    | eval motion --trials 1 --workers 1 --primitives ,
eval motion    | eval motion --trials 1 --workers 1 --primitives place,place
bench collect  | bench collect --samples 1 --workers 1 --primitives ''
bench collect  | bench collect --samples 1 --workers 1 --primitives wizard
bench push-settings | bench push-settings --scenes 1 --trials 1 --setting ''
bench push-settings | bench push-settings --scenes 1 --trials 1 --setting 0:1
bench compare-trials | bench compare-trials missing.npz missing.npz
bench compare-trials | bench compare-trials . .
eval           | eval world --sizes 2 --goals 1 --workers 1 --out run --ray ''
eval           | eval world --sizes 2 --goals 1 --workers 1 --out run --rules-off wizard
eval           | eval world --sizes 2 --goals 1 --out run --rules-off push_give_up,,least_taken
eval           | eval world --sizes 2 --goals 1 --out run --protocol paper --rules-off push_give_up
eval           | eval world --sizes 2 --goals 1 --workers 1 --out run --protocol ''
eval           | eval world --sizes 2 --goals 1 --out run --ablate-rules --protocol paper
eval           | eval world --sizes 2 --goals 1 --workers 1 --out run --ray 127.0.0.1:1
collect place  | collect place --samples 1 --workers 1 --out ds --ray ''
collect place  | collect place --samples 1 --workers 1 --out ds --ray 127.0.0.1:1
collect reach  | collect reach --states 1 --workers 1 --out ds --ray ''
collect reach  | collect reach --states 1 --workers 1 --out ds --ray 127.0.0.1:1
demo           | demo --out pics --agent wizard
demo           | demo --out pics --motion ''
eval task      | eval task --planner wizard
plan           | plan --goal 'On(butter, shelf_a)' --search wizard
plan           | plan --goal 'On(butter, shelf_a)' --names wizard
plan           | plan --goal 'On(butter, shelf_a)' --names ''
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
