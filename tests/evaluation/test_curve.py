"""Learning curves: points read from eval task runs and their checkpoints, never typed."""

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from hsgplan.cli import app
from hsgplan.domain.errors import InvalidInputError
from hsgplan.evaluation.curve import curve_points, curve_table, demonstrations_of

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
    title, points = curve_points([("recipe", [big, small])])
    assert [p.demonstrations for p in points] == [6, 18]
    assert points[0].success == {2: 0.5, 3: 0.0} and points[1].completion == {2: 1.0, 3: 0.75}
    assert "paper protocol" in title and "2 goals per size" in title
    table = curve_table(title, points)
    assert table.rows[0] == ("recipe", "6", "0.50 / 0.75", "0.00 / 0.50")
    assert table.rows[-1][0].startswith("the paper's Table 1")


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
        curve_points([("s", [a, b])])
    c = _run(tmp_path / "c", _checkpoint(tmp_path / "cc", 12), {2: 1}, protocol="recovering")
    with pytest.raises(InvalidInputError, match="differ in protocol"):
        curve_points([("s", [a]), ("t", [c])])


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
