"""The command line: output shapes, and bad input refused with one line and exit code 2."""

import json
import re

import pytest
from typer.testing import CliRunner

from hsgplan.cli import app
from hsgplan.domain.goals import parse_goal, read_goal_file
from hsgplan.domain.kitchen import KITCHEN

runner = CliRunner()


WORLD = ("eval", "world")


def run(*args):
    return runner.invoke(app, list(args))


def test_plan_json_lists_every_step_with_its_state():
    r = run("plan", "--goal", "On(butter, cherries) & In(tomato_soup, shelf_a)", "--json")
    assert r.exit_code == 0, r.output
    steps = json.loads(r.stdout)
    assert steps[0]["action"] is None and steps[0]["step"] == 0
    actions = [s["action"] for s in steps[1:]]
    assert len(actions) == 5  # the shortest plan: two steps for butter, three for the soup
    assert {"place(butter, cherries)", "push(tomato_soup, shelf_a)"} <= set(actions)
    final = parse_goal(" & ".join(steps[-1]["state"]), validate=False, world=KITCHEN)
    assert {str(x) for x in final.literals} >= {"On(butter, cherries)", "In(tomato_soup, shelf_a)"}


def test_plan_from_a_given_start_with_extra_objects():
    r = run(
        "plan",
        "--goal",
        "On(butter, shelf_a)",
        "--names",
        "butter,cherries",
        "--init",
        "On(butter, open_space) & On(cherries, butter)",
    )
    assert r.exit_code == 0, r.output
    assert "pick(cherries)" in r.stdout and "goal holds: True" in r.stdout


def test_goals_file_is_deterministic(tmp_path):
    a, b = tmp_path / "a.txt", tmp_path / "b.txt"
    for path in (a, b):
        r = run("goals", "--objects", "4", "--goals", "7", "--seed", "3", "--out", str(path))
        assert r.exit_code == 0, r.output
    assert a.read_text() == b.read_text()
    goals = read_goal_file(a, world=KITCHEN)
    assert len(goals) == 7 and all(g.size == 4 for g in goals)
    r = run("goals", "--objects", "4", "--goals", "7", "--seed", "3")
    assert r.stdout == a.read_text()


def test_bench_symbolic_prints_a_row_per_size_and_search():
    r = run("bench", "symbolic", "--sizes", "2-3", "--goals", "2", "--json")
    assert r.exit_code == 0, r.output
    rows = json.loads(r.stdout)
    assert [(x["size"], x["planner"]) for x in rows] == [
        (2, "fd-wastar"),
        (2, "fd-optimal"),
        (3, "fd-wastar"),
        (3, "fd-optimal"),
    ]
    assert all(x["solved"] == 2 and x["median_seconds"] > 0 for x in rows)


BAD = [
    (["plan", "--goal", "On(banana, shelf_a)"], "unknown name 'banana'"),
    (["plan", "--goal", "On(butter, cherries) & On(cherries, butter)"], "cycle"),
    (["plan", "--goal", "InGrasp(butter) & InGrasp(cherries)"], "one object at a time"),
    (["plan", "--goal", "In(popcorn, shelf_a)"], "does not fit"),
    (["plan", "--goal", ""], "empty"),
    (["plan", "--goal", "On(butter, shelf_a)", "--names", "cherries"], "lacks 'butter'"),
    (["plan", "--goal", "On(butter, shelf_a)", "--names", "butter,pear"], "unknown name 'pear'"),
    (["plan", "--goal", "On(butter, shelf_a)", "--init", "On(butter, butter)"], "itself"),
    (
        ["plan", "--goal", "On(butter, shelf_a)", "--init", "On(cherries, shelf_a)"],
        "not in the scene",
    ),
    (["plan", "--goal", "On(cherries, shelf_b)", "--init", "In(cherries, shelf_a)"], "no sequence"),
    (["goals", "--objects", "4", "--goals", "-3"], "greater than or equal to 1"),
    (["goals", "--objects", "13", "--goals", "3"], "between 2 and 12"),
    (["goals", "--objects", "0", "--goals", "3"], "between 2 and 12"),
    (["bench", "symbolic", "--sizes", "2-x"], "expected a range"),
    (["bench", "symbolic", "--sizes", "1-3"], "between 2 and 12"),
    (["bench", "symbolic", "--goals", "-1"], "greater than or equal to 1"),
    (["demo", "--objects", "40"], "between 2 and 12"),
    (["demo", "--agent", "wizard"], "'wizard' is not one of 'oracle'"),
    (["demo", "--goal", "On(butter, butter)"], "itself"),
    ([*WORLD, "--sizes", "2", "--goals", "0"], "greater than or equal to 1"),
    ([*WORLD, "--sizes", "2", "--workers", "0"], "greater than or equal to 1"),
    ([*WORLD, "--motion", "wizard"], "unknown motion generator 'wizard'"),
    (
        [*WORLD, "--planner", "regression", "--motion", "gnn,wand"],
        "unknown motion generator 'wand'",
    ),
    ([*WORLD, "--motion", "gnn,gnn"], "name each generator once"),
    ([*WORLD, "--sizes", "2", "--repeats", "0"], "greater than or equal to 1"),
    ([*WORLD, "--sizes", "1-6"], "between 2 and 12"),
    ([*WORLD, "--sizes", "2-13"], "between 2 and 12"),
    ([*WORLD, "--agent", "learned", "--checkpoint", "/nonexistent/task"], "/nonexistent/task"),
    ([*WORLD, "--agent", "learned", "--motion-checkpoints", "/nonexistent/m"], "/nonexistent/m"),
    ([*WORLD, "--goals-file", "/nonexistent/goals.txt"], "does not exist"),
    ([*WORLD, "--sizes", "2", "--perception", "sonar"], "--perception 'sonar': one of gt, rgb"),
    ([*WORLD, "--sizes", "2", "--perception", "gt,gt"], "name each observer once"),
    (
        [*WORLD, "--sizes", "2", "--perception", "rgb", "--perception-checkpoint", "/no/f_p"],
        "/no/f_p",
    ),
    (["demo", "--perception", "sonar"], "'sonar' is not one of 'gt', 'rgb'"),
    (["demo", "--rerun", "episode.mp4"], "a recording's file ends in .rrd"),
    (["demo", "--perception", "rgb", "--perception-checkpoint", "/no/f_p"], "/no/f_p"),
    (["bench", "sim", "--episodes", "0"], "greater than or equal to 1"),
    (["plan", "--goal", "On(cherries, shelf_a) &"], "ends with '&'"),
    ([*WORLD, "--goals", "many"], "valid integer"),
    (["eval", "task", "--planner", "wizard"], "'wizard' is not one of 'regression'"),
    (["eval", "motion", "--workers", "0"], "greater than or equal to 1"),
    (["bench", "timing", "--goals", "0"], "greater than or equal to 1"),
    (["bench", "timing", "--sizes", "1-3"], "between 2 and 12"),
    (["bench", "timing", "--workers", "0"], "greater than or equal to 1"),
    ([*WORLD, "--agent", "search", "--motion", "gnn"], "no task planner or motion generator"),
    (["report", "/nonexistent/run"], "is not a folder"),
    (["report", "/nonexistent/run", "--failures", "-1"], "greater than or equal to 0"),
    (["collect", "images", "--samples", "1", "--views", "9"], "views 9: there are 1 to 5"),
    (["collect", "images", "--samples", "1", "--views", "0"], "greater than or equal to 1"),
    (["eval", "perception", "--scenes", "1", "--views", "6"], "views 6: there are 1 to 5"),
    ([*WORLD, "--tables", "success,plots"], "no table 'plots'"),
    (["eval", "world", "--goals", "100001"], "less than or equal to 100000"),
    (["collect", "push", "--scene", "scenes/new-objects"], "round scenes of the same types"),
    (["bench", "collect", "--scene", "scenes/new-objects"], "round scenes of the same types"),
    (["eval", "task", "--planner", "regression-ahead-checked"], "is not one of 'regression'"),
]


@pytest.mark.parametrize(("args", "reason"), BAD, ids=[" ".join(a)[:40] for a, _ in BAD])
def test_bad_input_gets_one_line_and_exit_code_2(args, reason):
    r = run(*args)
    assert r.exit_code == 2, r.output
    lines = [line for line in r.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:"), r.stderr
    assert reason in lines[0]
    assert "Traceback" not in r.output


def test_goals_replace_an_existing_goal_file(tmp_path):
    path = tmp_path / "goals.txt"
    path.write_text("On(butter, shelf_a)\n")
    r = run("goals", "--objects", "4", "--goals", "3", "--out", str(path))
    assert r.exit_code == 0, r.output
    assert len(read_goal_file(path, world=KITCHEN)) == 3
    assert sorted(p.name for p in tmp_path.iterdir()) == ["goals.txt"]


def test_refused_command_leaves_an_existing_file_alone(tmp_path):
    path = tmp_path / "goals.txt"
    path.write_text("On(butter, shelf_a)\n")
    r = run("goals", "--objects", "4", "--goals", "-1", "--out", str(path))
    assert r.exit_code == 2
    assert path.read_text() == "On(butter, shelf_a)\n"


@pytest.mark.parametrize(
    "args, hint",
    [
        (["eval-task", "--sizes", "2"], "'hsgplan eval-task' is now 'hsgplan eval task'"),
        (["eval-perception"], "'hsgplan eval-perception' is now 'hsgplan eval perception'"),
        (["eval", "--protocol", "paper"], "'hsgplan eval world --protocol paper ...'"),
        (["goals", "--objects", "3", "--count", "2"], "'hsgplan goals --count' is now '--goals'"),
        (["plan", "--goal", "On(butter, shelf_a)", "--objects=butter"], "is now '--names'"),
        (["eval", "reach", "--trials", "x"], "'hsgplan eval reach --trials' is now '--data'"),
        (["eval", "motion", "--checkpoints", "m"], "is now '--motion-checkpoints'"),
        (["collect", "images", "--count", "1"], "is now '--samples'"),
        (["demo", "--agent", "paper"], "'--agent paper' is now '--agent learned'"),
        ([*WORLD, "--agent=paper"], "'--agent paper' is now '--agent learned'"),
    ],
)
def test_older_spellings_are_refused_with_the_new_one(args, hint):
    r = run(*args)
    assert r.exit_code == 2
    lines = [line for line in r.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and hint in lines[0]


def test_the_new_spellings_are_not_mistaken_for_older_ones():
    from hsgplan.cli.renamed import hint

    assert hint([*WORLD, "--sizes", "2"]) is None
    assert hint(["goals", "--objects", "3", "--goals", "2"]) is None
    assert hint(["eval", "--help"]) is None
    assert hint(["eval", "task", "--checkpoints", "x"]) is None  # the option is eval motion's
    assert hint([]) is None
    assert hint([*WORLD, "--protocol", "paper"]) is None  # the protocol keeps its name


def test_every_count_and_seed_takes_its_bounds_from_the_one_table():
    import typer.main

    from hsgplan.domain.checks import BOUNDS

    def commands(group, path=()):
        for name, cmd in group.commands.items():
            if hasattr(cmd, "commands"):
                yield from commands(cmd, (*path, name))
            else:
                yield (*path, name), cmd

    checked = 0
    for path, cmd in commands(typer.main.get_command(app)):
        for param in cmd.params:
            if param.name not in BOUNDS or param.min is None:
                continue
            expected = (BOUNDS[param.name]["lo"], BOUNDS[param.name]["hi"])
            # the upper bound is checked by the option's callback (`cli.common.at_most`)
            assert (param.min, param.callback.hi) == expected, (path, param.name)
            checked += 1
    assert checked >= 20  # seeds, goals, workers, samples, ... across the commands


def test_every_command_list_shows_each_command_in_one_paragraph():
    """A group's command list summarises each command by its docstring's first paragraph,
    with the docstring's line breaks joined (`cli.common.Summaries`)."""
    import typer.main

    def groups(group):
        yield group
        for name in group.list_commands(None):
            cmd = group.get_command(None, name)
            if hasattr(cmd, "list_commands"):  # typer ships its own click: no isinstance
                yield from groups(cmd)

    seen = 0
    for group in groups(typer.main.get_command(app)):
        for name in group.list_commands(None):
            cmd = group.get_command(None, name)
            first = cmd.help.split("\n\n")[0]
            assert cmd.short_help == " ".join(first.split()), name
            seen += "\n" in first
    assert seen >= 5  # docstrings that wrap their first paragraph are among them


def test_a_commands_defaults_are_its_configurations_defaults():
    """Where an option sets a configuration's field, its default and bounds are the field's
    (read from it by `cli.common.config_default` and `config_option`)."""
    import dataclasses

    import typer.main

    from hsgplan.collect.images import ImagesConfig
    from hsgplan.collect.motion import CollectConfig
    from hsgplan.evaluation.config import EvalConfig

    group = typer.main.get_command(app)

    def option(path: tuple[str, ...], name: str):
        cmd = group
        for part in path:
            cmd = cmd.commands[part]
        (param,) = [p for p in cmd.params if p.name == name]
        return param

    def field_of(config, name: str):
        (f,) = [f for f in dataclasses.fields(config) if f.name == name]
        return f

    pairs = [
        (("collect", "place"), "seed", CollectConfig, "seed"),
        (("collect", "place"), "workers", CollectConfig, "workers"),
        (("collect", "place"), "tasks_per_chunk", CollectConfig, "tasks_per_chunk"),
        (("collect", "push"), "tasks_per_chunk", CollectConfig, "tasks_per_chunk"),
        (("collect", "images"), "seed", ImagesConfig, "seed"),
        (("collect", "images"), "p_elsewhere", ImagesConfig, "p_elsewhere"),
        (("eval", "world"), "repeats", EvalConfig, "repeats"),
        (("eval", "world"), "perception", EvalConfig, "perception"),
        (("eval", "world"), "protocol", EvalConfig, "protocol"),
    ]
    for path, name, config, field in pairs:
        param, f = option(path, name), field_of(config, field)
        got = getattr(param.default, "value", param.default)  # an enum's choice
        assert got == f.default, (path, name)
        if "lo" in f.metadata:  # a bounded field: the option refuses what the field would
            assert (param.min, param.callback.hi) == (f.metadata["lo"], f.metadata["hi"])


def test_version_is_the_installed_packages():
    from importlib.metadata import version

    r = runner.invoke(app, ["--version"])
    assert r.exit_code == 0 and r.stdout.strip() == f"hsgplan {version('hsgplan')}"


def _help_at_80_columns(path: list[str], monkeypatch) -> str:
    monkeypatch.setenv("COLUMNS", "80")
    monkeypatch.setenv("TERM", "dumb")
    r = runner.invoke(app, [*path, "--help"], env={"COLUMNS": "80"})
    assert r.exit_code == 0, r.output
    return r.output


def test_help_reads_at_80_columns(monkeypatch):
    """Every option name whole, and eval world's descriptions at least 30 characters wide."""
    import typer.main

    def commands(group, path=()):
        for name, cmd in group.commands.items():
            if hasattr(cmd, "commands"):
                yield from commands(cmd, (*path, name))
            else:
                yield [*path, name]

    option = re.compile(r"^│\s+(?:\*\s+)?(--[\w-]+)(…?)")
    for path in commands(typer.main.get_command(app)):
        text = _help_at_80_columns(path, monkeypatch)
        assert max(len(line) for line in text.splitlines()) <= 80, path
        found = [m.groups() for m in map(option.match, text.splitlines()) if m]
        assert found and not [name for name, cut in found if cut], path
        assert not re.search(r"<(?:str|bool|int|float|Path)>", text), path  # Typer's own words
    text = _help_at_80_columns(["eval", "world"], monkeypatch)
    seed = next(line for line in text.splitlines() if option.match(line) and "--seed " in line)
    assert len(seed) - 2 - seed.index("Seed of the goals") >= 30


def test_a_piped_table_keeps_its_headers_whole(capsys):
    from hsgplan.cli.common import print_table

    header = tuple(f"header number {i}" for i in range(9))  # wider than 80 columns
    print_table("t", header, [tuple("1" for _ in header)], markdown=False)
    text = capsys.readouterr().out
    assert all(h in text for h in header) and "…" not in text


@pytest.mark.parametrize(
    "args", [["demo", "--rerun", "x/episode.rrd"], ["report", "/no/run", "--rerun"]]
)
def test_a_recording_without_rerun_installed_is_refused_in_one_line(args, monkeypatch, tmp_path):
    monkeypatch.setattr("hsgplan.evaluation.recording.available", lambda: False)
    monkeypatch.chdir(tmp_path)
    r = run(*args)
    assert r.exit_code == 2, r.output
    assert "--rerun needs rerun-sdk" in r.output and "Traceback" not in r.output
    assert list(tmp_path.iterdir()) == []  # nothing written


def test_a_kill_interrupts_as_ctrl_c_does_so_a_long_job_closes_what_it_opened():
    import subprocess
    import sys

    script = (
        "import os, signal, time\n"
        "from hsgplan.cli import interrupt_on_terminate\n"
        "interrupt_on_terminate()\n"
        "try:\n"
        "    os.kill(os.getpid(), signal.SIGTERM)\n"
        "    time.sleep(30)\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted')\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=60
    )
    assert done.stdout.strip() == "interrupted", done.stderr


def test_the_rules_page_lists_every_rule_a_run_may_set_with_what_it_does():
    from dataclasses import fields

    from hsgplan.domain.recovery import NO_FAILURE_RULES, RecoveryRules
    from hsgplan.perception.rules import PerceptionRules
    from hsgplan.sim.plan_rules import PlanRules

    r = run("rules", "--markdown")
    assert r.exit_code == 0, r.output
    rows = {line.split("|")[2].strip(): line for line in r.output.splitlines()[4:] if "|" in line}
    names = [
        *RecoveryRules.names(),
        *(f.name for f in fields(PerceptionRules)),
        *(f.name for f in fields(PlanRules)),
    ]
    assert sorted(rows) == sorted(names)
    for name, line in rows.items():
        what = line.split("|")[5].strip()
        assert len(what) > 20 and what.endswith("."), name
    assert "| kept |" in rows["relook"] and "| off |" in rows["least_taken"]
    assert all("| kept |" in rows[n] for n in NO_FAILURE_RULES)
    help_text = run("eval", "world", "--help").output
    assert "hsgplan rules" in help_text and "push_give_up" not in help_text
