"""Learning curves: points read from eval task runs and their checkpoints, never typed."""

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from hsgplan.cli import app
from hsgplan.domain.errors import InvalidInputError
from hsgplan.evaluation.curve import curve_table, curves, demonstrations_of

DEMOS = Path(__file__).resolve().parents[2] / "data" / "demos" / "v1"


def _checkpoint(folder: Path, limit: int | None) -> Path:
    folder.mkdir(parents=True)
    config = {"demos": str(DEMOS)} | ({"demo_limit": limit} if limit else {})
    (folder / "train_config.json").write_text(json.dumps(config))
    return folder


def _run(folder: Path, checkpoint: Path, wins: dict[int, int], protocol="paper") -> Path:
    """An eval task run of two goals per size, `wins[size]` of them solved."""
    folder.mkdir(parents=True)
    config = {"kind": "eval-task", "checkpoint": str(checkpoint), "protocol": protocol}
    (folder / "config.json").write_text(json.dumps(config))
    rows = []
    for size, won in wins.items():
        for k in range(2):
            result = {
                "size": size,
                "seed": size * 10 + k,
                "goal": f"goal-{size}-{k}",
                "success": k < won,
                "failure": None if k < won else "step_limit",
                "steps": 3,
                "fd_length": 2,
                "subgoal_completion": 1.0 if k < won else 0.5,
                "decision_ms": [1.0],
            }
            rows.append(json.dumps({"key": f"{size}-{k}", "result": result}))
    (folder / "episodes.jsonl").write_text("\n".join(rows) + "\n")
    return folder


def test_points_are_ordered_by_the_demonstrations_their_checkpoint_learned_from(tmp_path):
    big = _run(tmp_path / "r18", _checkpoint(tmp_path / "c18", None), {2: 2, 3: 1})
    small = _run(tmp_path / "r6", _checkpoint(tmp_path / "c6", 6), {2: 1, 3: 0})
    c = curves([("recipe", [big, small])])
    points = c.points
    assert [p.amount for p in points] == [6, 18] and c.unit == "demonstrations"
    assert points[0].success == {"2 objects": 0.5, "3 objects": 0.0}
    assert points[1].completion == {"2 objects": 1.0, "3 objects": 0.75}
    assert "paper protocol" in c.title and "2 goals per size" in c.title
    table = curve_table(c)
    assert table.rows[0] == ("recipe", "6", "0.50 / 0.75", "0.00 / 0.50")
    assert table.rows[-1] == (
        "the paper's Table 1 (GNN, in its world)",
        "18",
        "0.92 / 0.95",
        "0.89 / 0.95",
    )


def test_a_combined_checkpoint_counts_its_f_preimage_demonstrations(tmp_path):
    source = _checkpoint(tmp_path / "c4", 4)
    combined = tmp_path / "combined"
    combined.mkdir()
    (combined / "combined.json").write_text(json.dumps({"preimage": str(source), "reach": "x"}))
    assert demonstrations_of(combined) == 4


def test_runs_that_are_not_like_for_like_or_repeat_a_count_are_refused(tmp_path):
    a = _run(tmp_path / "a", _checkpoint(tmp_path / "ca", 6), {2: 1})
    b = _run(tmp_path / "b", _checkpoint(tmp_path / "cb", 6), {2: 2})
    with pytest.raises(InvalidInputError, match="both learned from 6"):
        curves([("s", [a, b])])
    c = _run(tmp_path / "c", _checkpoint(tmp_path / "cc", 12), {2: 1}, protocol="recovering")
    with pytest.raises(InvalidInputError, match="differ in protocol"):
        curves([("s", [a]), ("t", [c])])


def test_cli_writes_the_plot_and_refuses_a_bad_series_in_one_line(tmp_path):
    a = _run(tmp_path / "a", _checkpoint(tmp_path / "ca", 6), {2: 1, 3: 1})
    b = _run(tmp_path / "b", _checkpoint(tmp_path / "cb", 12), {2: 2, 3: 1})
    png = tmp_path / "curve.png"
    r = CliRunner().invoke(
        app, ["eval", "curve", "--series", f"s={a},{b}", "--plot", str(png), "--markdown"]
    )
    assert r.exit_code == 0, r.output
    assert "| s | 12 | 1.00 / 1.00 | 0.50 / 0.75 |" in r.stdout
    assert png.read_bytes()[:4] == b"\x89PNG"
    for bad in ("s", "=x", "s="):
        r = CliRunner().invoke(app, ["eval", "curve", "--series", bad])
        assert r.exit_code == 2 and len(r.stderr.strip().splitlines()) == 1, bad


def _motion_run(folder: Path, trials: int, wins: dict[str, int], scenes: int = 4) -> Path:
    """An eval motion run over `scenes` place scenes, `wins[model]` of them solved, of a
    checkpoint folder whose place GNN learned from `trials` examples."""
    checkpoints = folder / "checkpoints"
    (checkpoints / "place-gnn").mkdir(parents=True)
    record = {"training_examples": trials, "validation_examples": 0, "chosen_epoch": 1}
    (checkpoints / "place-gnn" / "training.json").write_text(json.dumps(record))
    run = folder / "run"
    run.mkdir()
    config = {"kind": "eval-motion", "seed": 0, "checkpoints": str(checkpoints)}
    (run / "config.json").write_text(json.dumps(config))
    rows = [
        # scene 0 a place on a crowded shelf top, where it is hardest
        {"task": k, "model": model, "crowding": 2 * (k == 0), "shelf_top": k == 0, "ok": k < won}
        for k in range(scenes)
        for model, won in wins.items()
    ]
    (run / "episodes.jsonl").write_text(json.dumps({"key": "place/0", "result": rows}) + "\n")
    return run


def test_motion_points_read_the_gnns_training_trials_and_refuse_other_scenes(tmp_path):
    more = _motion_run(tmp_path / "more", 800, {"gnn": 4, "random": 1})
    fewer = _motion_run(tmp_path / "fewer", 100, {"gnn": 2, "random": 1})
    c = curves([("GNN", [more, fewer])])
    crowded = {"GNN, crowded shelf tops": 1.0, "Random, crowded shelf tops": 1.0}
    assert [(p.amount, p.success) for p in c.points] == [
        (100, {"GNN": 0.5, "Random": 0.25} | crowded),
        (800, {"GNN": 1.0, "Random": 0.25} | crowded),
    ]
    assert c.columns == ("GNN", "GNN, crowded shelf tops", "Random", "Random, crowded shelf tops")
    assert curve_table(c).rows[-1] == ("GNN", "800", "1.000", "1.000", "0.250", "1.000")
    other = _motion_run(tmp_path / "other", 200, {"gnn": 1}, scenes=3)
    with pytest.raises(InvalidInputError, match="differ in seed or scenes"):
        curves([("GNN", [more, other])])
    config = json.loads((other / "config.json").read_text())
    del config["checkpoints"]
    (other / "config.json").write_text(json.dumps(config))
    with pytest.raises(InvalidInputError, match="names no motion checkpoints"):
        curves([("GNN", [other])])
    with pytest.raises(InvalidInputError, match="no finished push scene"):
        curves([("GNN", [more])], primitive="push")
    task = _run(tmp_path / "t", _checkpoint(tmp_path / "ct", 6), {2: 1})
    with pytest.raises(InvalidInputError, match="all eval task runs or all eval motion"):
        curves([("a", [more]), ("b", [task])])


def test_a_point_of_several_trainings_gives_its_mean_and_interval(tmp_path):
    # two trainings of each of two configurations, on the same episodes
    six = [_checkpoint(tmp_path / f"c6-{t}", 6) for t in (0, 1)]
    all18 = [_checkpoint(tmp_path / f"c18-{t}", None) for t in (0, 1)]
    runs = [
        _run(tmp_path / "r6-0", six[0], {2: 0}),
        _run(tmp_path / "r6-1", six[1], {2: 2}),
        _run(tmp_path / "r18-0", all18[0], {2: 2}),
        _run(tmp_path / "r18-1", all18[1], {2: 2}),
    ]
    c = curves([("recipe", runs)], trainings=2)
    assert [(p.amount, p.success) for p in c.points] == [
        (6, {"2 objects": 0.5}),
        (18, {"2 objects": 1.0}),
    ]
    low, high = c.points[0].interval["2 objects"]
    assert low <= 0.5 <= high and low < high  # the trainings disagree
    assert c.points[1].interval == {"2 objects": (1.0, 1.0)}
    assert curve_table(c).rows[0][2].startswith(f"0.50 ({low:.2f}–{high:.2f}) / ")
    with pytest.raises(InvalidInputError, match="all its 2 runs"):
        curves([("recipe", runs[:3])], trainings=2)
    with pytest.raises(InvalidInputError, match="learned from"):  # one point, two amounts
        curves([("recipe", [runs[0], runs[2]])], trainings=2)
    args = ["eval", "curve", "--series", f"recipe={','.join(map(str, runs))}", "--trainings"]
    plot = tmp_path / "curve.png"
    r = CliRunner().invoke(app, [*args, "2", "--markdown", "--plot", str(plot)])
    assert r.exit_code == 0 and "| recipe | 18 | 1.00 (1.00–1.00) / 1.00 |" in r.stdout
    assert plot.stat().st_size > 0  # the intervals drawn as bands


def test_a_motion_run_of_several_trainings_reads_their_interval_and_mean_trials(tmp_path):
    run = _motion_run(tmp_path / "one", 100, {"gnn": 2, "random": 1})
    rows = json.loads((run / "episodes.jsonl").read_text())["result"]
    rows = [r | {"training": t, "ok": r["ok"] if t == 0 else True} for t in (0, 1) for r in rows]
    (run / "episodes.jsonl").write_text(json.dumps({"key": "place/0", "result": rows}) + "\n")
    # the run's checkpoints a trainings folder: each training held out its own scenes
    trainings = tmp_path / "trainings"
    trainings.mkdir()
    (run.parent / "checkpoints").rename(trainings / "seed-0")
    (_motion_run(tmp_path / "two", 110, {"gnn": 1}).parent / "checkpoints").rename(
        trainings / "seed-1"
    )
    (trainings / "trainings.json").write_text(json.dumps({"trained": {"place-gnn": [0, 1]}}))
    config = json.loads((run / "config.json").read_text()) | {"checkpoints": str(trainings)}
    (run / "config.json").write_text(json.dumps(config))
    point = curves([("GNN", [run])]).points[0]
    assert point.amount == 105 and point.success["GNN"] == 0.75
    low, high = point.interval["GNN"]
    assert low < 0.75 < high
