"""Runs side by side: rows like for like, refused in one line where they are not."""

import json
from dataclasses import asdict

import pytest
from typer.testing import CliRunner

from hsgplan.cli import app
from hsgplan.domain.errors import InvalidInputError
from hsgplan.evaluation.compare import compare
from hsgplan.evaluation.episode import EpisodeRecord, StepRecord
from hsgplan.evaluation.summary import summarize
from hsgplan.runner.run_folder import CONFIG


def _record(seed: int, size: int, success: bool) -> EpisodeRecord:
    status = "success" if success else "no_ik"
    step = StepRecord(1, "InGrasp(butter)", "pick(butter)", "pick(obj=butter)", status, "", 0, 0, 0)
    failure = None if success else "failed_primitive"
    return EpisodeRecord(
        seed, "learned", "On(butter, shelf_a)", size, success, 0.5, failure, (step,), 1.0
    )


def _run(
    folder, wins, seed=0, protocol="paper", motion="m", method="gnn", scene=None, rules_off=()
):
    """A finished table folder whose `method` column won `wins[size]`."""
    folder.mkdir(parents=True)
    records = [_record(k, n, won) for n, outcomes in wins.items() for k, won in enumerate(outcomes)]
    settings = {"kind": "eval-table", "goals": len(next(iter(wins.values()))), "seed": seed}
    settings |= {"protocol": protocol, "rules_off": list(rules_off), "repeats": 1}
    settings |= {"goals_file": None}
    settings |= {"sizes": sorted(wins), "motion_checkpoints": motion, "scene": scene}
    (folder / CONFIG).write_text(json.dumps(settings))
    summary = {
        "protocol": protocol,
        "rules_off": list(rules_off),
        "methods": {
            method: {"agent": "learned", "wall_seconds": 1.0, "sittings": []} | summarize(records)
        },
        "goals": settings["goals"],
        "goals_file": None,
        "repeats": 1,
        "seed": seed,
        "run": str(folder),
    }
    (folder / "summary.json").write_text(json.dumps(summary))
    return folder


def test_each_run_is_a_row_of_its_success_per_size_and_the_paper_is_the_last(tmp_path):
    a = _run(tmp_path / "a", {2: (True, False), 3: (False, False)}, motion="ladder/a")
    b = _run(tmp_path / "b", {2: (True, True), 3: (True, False)}, motion="ladder/b")
    table = compare([a, b], ["theirs", "ours"], ["gnn"])
    assert table.header == ("run", "2 objects", "3 objects")
    assert [r[0] for r in table.rows] == ["theirs", "ours", "GNN (paper)"]
    assert table.rows[0][1].startswith("0.50") and table.rows[1][1].startswith("1.00")
    assert table.rows[1][2].startswith("0.50") and table.rows[2][1] == "0.92 / 0.95"
    assert "paper protocol" in table.title and "each run once" in table.title


@pytest.mark.parametrize(
    ("other", "says"),
    [
        ({"seed": 1}, "differ in seed"),
        ({"protocol": "recovering"}, "differ in protocol"),
        ({"scene": "scenes/layouts"}, "differ in scene"),
        ({"rules_off": ("refuse_repeats",)}, "differ in rules_off"),
    ],
)
def test_runs_that_are_not_like_for_like_are_refused(tmp_path, other, says):
    a = _run(tmp_path / "a", {2: (True,)})
    b = _run(tmp_path / "b", {2: (True,)}, **other)
    with pytest.raises(InvalidInputError, match=says):
        compare([a, b], ["a", "b"], ["gnn"])


def test_each_run_may_name_its_own_method_and_then_no_paper_row_is_set_beside(tmp_path):
    a = _run(tmp_path / "a", {2: (True, False)})
    b = _run(tmp_path / "b", {2: (True, True)}, method="gnn-checked")
    table = compare([a, b], ["gnn", "gnn-checked"], ["gnn", "gnn-checked"])
    assert [r[:2] for r in table.rows] == [
        ("gnn", "0.50 / 0.50"),  # one goal, run twice: no interval over goals
        ("gnn-checked", "1.00 / 0.50"),
    ]
    assert "each run's method" in table.title
    with pytest.raises(InvalidInputError, match="one, or one per run"):
        compare([a, b], ["a", "b"], ["gnn", "gnn", "gnn"])
    r = CliRunner().invoke(app, ["eval", "compare", str(a), str(b), "--method", "gnn,gnn-checked"])
    assert r.exit_code == 0 and "1.00 / 0.50" in r.stdout


def test_a_missing_method_or_a_name_short_is_one_line_exit_2(tmp_path):
    a = _run(tmp_path / "a", {2: (True,)})
    with pytest.raises(InvalidInputError, match="holds no method 'mlp'"):
        compare([a], ["a"], ["mlp"])
    r = CliRunner().invoke(app, ["eval", "compare", str(a), str(a), "--names", "x"])
    assert r.exit_code == 2 and "2 runs and 1 names" in r.stderr
    r = CliRunner().invoke(app, ["eval", "compare", str(a), "--markdown"])
    assert r.exit_code == 0 and "| a | 1.00 / " in r.stdout


def _task_run(folder, successes, protocol="paper", seeds=(1, 2), scenes=("",)):
    from hsgplan.evaluation.task_eval import TaskEpisode

    folder.mkdir()
    config = {"kind": "eval-task", "planner": "regression", "checkpoint": "c"}
    config |= {"scene": "scenes" if scenes != ("",) else None}
    (folder / "config.json").write_text(json.dumps(config | {"protocol": protocol}))
    lines = []
    for scene in scenes:  # a folder of scenes keys its episodes by scene first
        for seed, ok in zip(seeds, successes, strict=True):
            goal = "On(cherries, shelf_a) & On(butter, shelf_b)"
            ep = TaskEpisode(2, seed, goal, ok, None if ok else "no_subgoal", 3, 3, 1.0, (1.0,))
            key = f"{scene}/{seed}/{goal}" if scene else f"{seed}/{goal}"
            lines.append(json.dumps({"key": key, "result": asdict(ep)}))
    (folder / "episodes.jsonl").write_text("\n".join(lines) + "\n")
    return folder


def test_task_runs_are_compared_on_the_same_episodes(tmp_path):
    from hsgplan.evaluation.compare import all_task_runs, compare_task

    a, b = _task_run(tmp_path / "a", (True, False)), _task_run(tmp_path / "b", (True, True))
    assert all_task_runs([a, b])
    table = compare_task([a, b], ["theirs", "ours"])
    assert [row[1].split(" / ")[0] for row in table.rows] == ["0.50", "1.00"]
    assert "paper protocol" in table.title and table.title.endswith(": 2 goals per size")
    folders = [_task_run(tmp_path / n, (True, True), scenes=("s1", "s2", "3")) for n in "ef"]
    assert compare_task(folders, ["e", "f"]).title.endswith("2 goals per size in each of 3 scenes")
    other = _task_run(tmp_path / "c", (True, True), seeds=(1, 3))
    with pytest.raises(InvalidInputError, match="differ in episodes"):
        compare_task([a, other], ["a", "c"])
    recovering = _task_run(tmp_path / "d", (True, True), protocol="recovering")
    with pytest.raises(InvalidInputError, match="differ in protocol"):
        compare_task([a, recovering], ["a", "d"])


def test_runs_of_one_agent_in_different_scenes_stand_side_by_side_on_as_many_episodes(tmp_path):
    kitchen = _run(tmp_path / "kitchen", {2: (True, True, True, True)})
    layouts = _run(tmp_path / "layouts", {2: (True, False)}, scene="scenes/layouts")
    summary = json.loads((layouts / "summary.json").read_text())
    summary["methods"]["gnn"]["by_size"]["2"]["episodes"] = 4  # 2 goals in each of 2 scenes
    (layouts / "summary.json").write_text(json.dumps(summary))
    table = compare([kitchen, layouts], ["kitchen", "layouts"], ["gnn"], across_scenes=True)
    assert [r[0] for r in table.rows[:2]] == ["kitchen", "layouts"]
    assert table.rows[0][1].startswith("1.00") and table.rows[1][1].startswith("0.50")
    assert "by scene" in table.title and "4 episodes per size" in table.title
    with pytest.raises(InvalidInputError, match="differ in goals"):  # like for like, unless told
        compare([kitchen, layouts], ["kitchen", "layouts"], ["gnn"])
    fewer = _run(tmp_path / "fewer", {2: (True, False)}, scene="scenes/layouts")
    with pytest.raises(InvalidInputError, match="ran 2 episodes of 2 objects"):
        compare([kitchen, fewer], ["kitchen", "fewer"], ["gnn"], across_scenes=True)
    other = _run(tmp_path / "other", {2: (True, True, True, True)}, seed=3, scene="x")
    with pytest.raises(InvalidInputError, match="differ in seed"):
        compare([kitchen, other], ["kitchen", "other"], ["gnn"], across_scenes=True)


def test_a_ladder_of_recovery_rules_stands_side_by_side_when_told(tmp_path):
    off = _run(tmp_path / "off", {2: (True, False)}, rules_off=("refuse_repeats",))
    on = _run(tmp_path / "on", {2: (True, True)})
    table = compare([off, on], ["without", "with"], ["gnn"], across_rules=True)
    assert table.rows[0][1].startswith("0.50") and table.rows[1][1].startswith("1.00")
    assert "rules by row" in table.title and "without refuse_repeats" not in table.title
    seeded = _run(tmp_path / "seeded", {2: (True, True)}, seed=4)
    with pytest.raises(InvalidInputError, match="differ in seed"):  # the rest stays like for like
        compare([off, seeded], ["off", "seeded"], ["gnn"], across_rules=True)


def test_every_rule_on_under_the_recovering_protocol_stands_beside_one_off(tmp_path):
    # a recovering run with every rule on writes no protocol (as runs did before protocols
    # were named); it is still the recovering protocol, not another
    on = _run(tmp_path / "on", {2: (True, True)}, protocol="recovering")
    config = json.loads((on / CONFIG).read_text())
    del config["protocol"], config["rules_off"]
    (on / CONFIG).write_text(json.dumps(config))
    off = _run(tmp_path / "off", {2: (True, False)}, protocol="recovering", rules_off=("x",))
    table = compare([on, off], ["on", "off"], ["gnn"], across_rules=True)
    assert table.rows[1][1].startswith("0.50")
    paper = _run(tmp_path / "paper", {2: (True, True)})
    with pytest.raises(InvalidInputError, match="differ in protocol"):
        compare([on, paper], ["on", "paper"], ["gnn"], across_rules=True)


def test_task_runs_of_three_trainings_make_one_row_with_an_interval(tmp_path):
    from hsgplan.evaluation.compare import compare_task_trainings

    seeds = (1, 2, 3, 4)
    ours = [_task_run(tmp_path / f"o{k}", (True, True, True, k > 0), seeds=seeds) for k in range(3)]
    theirs = [
        _task_run(tmp_path / f"t{k}", (True, False, False, False), seeds=seeds) for k in range(3)
    ]
    table = compare_task_trainings([*theirs, *ours], ["theirs", "ours"], 3)
    cells = [row[1] for row in table.rows]
    assert cells[0].startswith("0.25 (") and cells[1].startswith("0.92 (")
    low, high = (float(v) for v in cells[1].split("(")[1].split(")")[0].split("–"))
    assert low < 0.92 <= high <= 1.0  # a training that lost a goal widens the interval
    their_high = float(cells[0].split("–")[1].split(")")[0])
    assert their_high >= low and not cells[1].endswith("▲")  # the intervals overlap
    never = [_task_run(tmp_path / f"n{k}", (False,) * 4, seeds=seeds) for k in range(3)]
    table = compare_task_trainings([*never, *ours], ["never", "ours"], 3)
    assert table.rows[1][1].endswith("▲") and "▲ (▼)" in table.title
    assert "each run once under each of 3 trainings" in table.title
    args = ["eval", "compare", *map(str, [*theirs, *ours]), "--trainings", "3"]
    r = CliRunner().invoke(app, [*args, "--names", "theirs,ours", "--markdown"])
    assert r.exit_code == 0 and "| ours | 0.92 (" in r.stdout
    r = CliRunner().invoke(app, [*args[:-2], "--trainings", "4"])
    assert r.exit_code == 2 and "rows of 4 trainings" in r.stderr


def test_the_method_compared_is_the_one_every_run_holds_else_gnn(tmp_path):
    from hsgplan.evaluation.compare import only_method

    agent = [_run(tmp_path / f"a{k}", {2: (True, k > 0)}, method="learned") for k in range(2)]
    assert only_method(agent) == "learned"
    table = compare(agent, ["a0", "a1"], [only_method(agent)])
    assert table.rows[0][1].startswith("0.50") and table.rows[1][1].startswith("1.00")
    mixed = [agent[0], _run(tmp_path / "g", {2: (True, True)})]
    assert only_method(mixed) == "gnn"  # runs of different methods: Table 1's column
    assert only_method([tmp_path / "nothing"]) == "gnn"  # refused where it is read
    r = CliRunner().invoke(app, ["eval", "compare", str(agent[0]), str(agent[1])])
    assert r.exit_code == 0 and "learned" in r.output, r.output


def test_a_row_is_marked_only_where_its_interval_clears_the_row_aboves():
    from hsgplan.evaluation.compare import marked_rows

    rows = [("a", "0.50", "0.50"), ("b", "0.90", "0.55"), ("c", "0.40", "0.50")]
    intervals = [[(0.4, 0.6), (0.4, 0.6)], [(0.8, 1.0), (0.45, 0.65)], [(0.3, 0.5), None]]
    marked = marked_rows(rows, intervals)
    assert marked[0] == rows[0]  # the first row has none above it
    assert marked[1] == ("b", "0.90 ▲", "0.55")  # the second cell's intervals overlap
    assert marked[2] == ("c", "0.40 ▼", "0.50")  # no interval, no mark
    # across scenes each row is set against the first (the kitchen)
    against = marked_rows(rows, intervals, against_first=True)
    assert against[2] == ("c", "0.40", "0.50")  # overlaps the first row's
