"""`hsgplan bench push-reach|line-error|push-settings|compare-trials`: each runs on a task or
two, leaves the constants it varies as they were, and refuses bad input in one line."""

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from hsgplan.benchmarks.compare_trials import compare
from hsgplan.benchmarks.line_error import summarize as line_summary
from hsgplan.benchmarks.push_reach import reach_margin
from hsgplan.benchmarks.push_reach import summarize as reach_summary
from hsgplan.benchmarks.push_settings import PushSetting, parse_setting
from hsgplan.cli import app
from hsgplan.data import motion_store, motion_trials
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.parameters import PUSH_LEAD, MotionPrimitive
from hsgplan.sim import motion_plans, primitives

runner = CliRunner()
PUSH = MotionPrimitive.PUSH
LAYOUTS = Path(__file__).resolve().parents[2] / "scenes" / "layouts"


def bench(*args):
    return runner.invoke(app, ["bench", *args])


def test_the_margin_is_how_far_the_bound_ends_past_the_front():
    assert reach_margin(0.5, 0.0, PUSH_LEAD + 0.1, 0.55) == pytest.approx(0.05)
    assert reach_margin(0.5, np.pi / 3, PUSH_LEAD + 0.2, 0.5) == pytest.approx(0.1)


def test_the_reach_report_takes_the_smallest_success_and_counts_under_the_slack():
    margins = [(0.03, True), (0.05, True), (0.01, False), (0.02, False), (-0.1, False)]
    report = reach_summary(margins, {"success": 2, "no_path": 3}, slack=0.025)
    assert (report.trials, report.successes) == (5, 2)
    assert report.smallest_margin_of_a_success_m == 0.03
    assert report.trials_under_the_slack == 3
    assert reach_summary([(0.1, False)], {}, 0.025).smallest_margin_of_a_success_m is None


def test_the_line_report_in_millimetres_and_none_without_a_line():
    report = line_summary(8, 2, [0.001, 0.003])
    assert (report.mean_mm, report.max_mm) == (2.0, 3.0)
    assert line_summary(4, 0, []).mean_mm is None


def test_a_setting_is_substeps_and_attempts_and_its_speed():
    assert parse_setting(" 3:8") == PushSetting(3, 8)
    assert PushSetting(3, 8).speed == pytest.approx(0.4)
    assert PushSetting(2, 4).speed == pytest.approx(0.6)


def test_trials_are_compared_by_task_and_attempt():
    old = {(0, 0): ((1, 2), 0), (0, 1): ((3, 4), 1), (1, 0): ((5, 5), 1), (2, 0): ((0, 0), 0)}
    new = {(0, 0): ((1, 2), 0), (0, 1): ((3, 4), 0), (1, 0): ((6, 5), 0), (9, 0): ((0, 0), 0)}
    report = compare(old, new)
    assert (report.shared, report.same_outcome, report.other_bins) == (3, 1, 1)
    assert report.changed == {f"{motion_store.STATUSES[1].value} -> success": 1}


def _trials_file(path, statuses):
    """Push trials of task 0.., attempt 0, bins (1, 1), the can alone in the scene."""
    n = len(statuses)
    poses = np.full((n, len(motion_store.TYPES), 7), np.nan, dtype=np.float32)
    poses[:, 0] = [0.5, 0.0, 0.8, 0.0, 0.0, 0.0, 1.0]
    small = np.zeros(n, dtype=np.int8)
    data = motion_store.MotionData(
        PUSH,
        np.arange(n, dtype=np.int32),
        small,
        np.array(statuses, dtype=np.int8),
        small,
        small,
        np.full(n, KITCHEN.entity_types.index("shelf_a"), dtype=np.int8),
        np.ones((n, 2), dtype=np.int8),
        poses,
        KITCHEN,
    )
    motion_store.save(path, data)


def test_compare_trials_reads_a_file_against_a_folder_of_chunks(tmp_path):
    _trials_file(tmp_path / "old.npz", [0, 1, 1])
    (tmp_path / "work").mkdir()
    _trials_file(motion_store.chunk_path(tmp_path / "work", 0), [0, 0, 1])
    r = bench("compare-trials", str(tmp_path / "old.npz"), str(tmp_path / "work"), "--json")
    assert r.exit_code == 0, r.output
    changed = {f"{motion_store.STATUSES[1].value} -> success": 1}
    assert json.loads(r.stdout) == {
        "shared": 3,
        "same_outcome": 2,
        "other_bins": 0,
        "changed": changed,
    }


def test_each_measurement_runs_on_one_task_and_restores_the_constants():
    saved = (
        motion_plans.PUSH_SLACK,
        motion_plans.LINE_IK_EVERY,
        motion_plans._line,
        primitives.PUSH_SUBSTEPS,
        dict(motion_trials.ATTEMPTS_PER_TASK),
    )
    r = bench("push-reach", "--tasks", "1", "--json")
    assert r.exit_code == 0, r.output
    reach = json.loads(r.stdout)
    assert reach["trials"] == sum(reach["statuses"].values()) > 0
    r = bench("line-error", "--tasks", "1", "--every", "8", "--every", "4", "--json")
    assert r.exit_code == 0, r.output
    assert [row["every"] for row in json.loads(r.stdout)] == [8, 4]
    r = bench("push-settings", "--scenes", "1", "--trials", "2", "--setting", "3:2", "--json")
    assert r.exit_code == 0, r.output
    (row,) = json.loads(r.stdout)
    assert (row["substeps"], row["attempts"], row["trials"]) == (3, 2, 2)
    assert saved == (
        motion_plans.PUSH_SLACK,
        motion_plans.LINE_IK_EVERY,
        motion_plans._line,
        primitives.PUSH_SUBSTEPS,
        motion_trials.ATTEMPTS_PER_TASK,
    )


def test_given_worlds_each_task_or_client_is_staged_in_its_own_in_turn(monkeypatch):
    from hsgplan.benchmarks import line_error, push_reach, push_settings
    from hsgplan.domain.scene_file import read_worlds

    worlds = list(read_worlds(LAYOUTS).values())[:2]
    drawn = []

    def draw(primitive, seed, index, world):
        drawn.append((index, worlds.index(world)))
        return None

    for module in (push_reach, line_error):
        monkeypatch.setattr(module, "draw_task", draw)
        monkeypatch.setattr(module, "run_task", lambda scene, task: [])
    push_reach.push_reach(3, 10, worlds=worlds)
    assert sorted(drawn) == [(10, 0), (11, 1), (12, 0)]
    drawn.clear()
    line_error.line_error(3, 4, worlds=worlds)
    assert sorted(drawn) == [(0, 0), (1, 1), (2, 0)]
    drawn.clear()
    monkeypatch.setattr(push_settings, "draw_task", lambda p, seed, i, w: draw(p, seed, seed, w))
    monkeypatch.setattr(push_settings.motion_trials, "run_task", lambda scene, task: [])
    push_settings.push_settings(3, 2, PushSetting(3, 2), worlds=worlds)
    first = push_settings.FIRST_SEED
    assert sorted(drawn) == [(first, 0), (first + 1, 1), (first + 2, 0)]


def test_a_measurement_runs_round_a_folder_of_scenes():
    r = bench("push-reach", "--tasks", "2", "--scene", str(LAYOUTS), "--json")
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout)["trials"] > 0


BAD = [
    (["line-error", "--scene", "nope.toml"], "scene file 'nope.toml' does not exist"),
    (["push-reach", "--tasks", "-1"], "greater than or equal to 1"),
    (["push-reach", "--first", "-5"], "greater than or equal to 0"),
    (["line-error", "--tasks", "0"], "greater than or equal to 1"),
    (["line-error", "--every", "0"], "greater than or equal to 1"),
    (["push-settings", "--scenes", "-1"], "greater than or equal to 1"),
    (["push-settings", "--setting", "3"], "expected SUBSTEPS:ATTEMPTS"),
    (["push-settings", "--setting", "0:4"], "substeps must be 1 to"),
    (["push-settings", "--setting", "3:0"], "attempts must be 1 to"),
    (["push-settings", "--trials", "4", "--setting", "3:8"], "more attempts a scene than"),
    (["compare-trials", "/nonexistent/old.npz", "/nonexistent/new.npz"], "no such motion data"),
    (["compare-trials", ".", "."], "without chunk files"),
]


@pytest.mark.parametrize(("args", "reason"), BAD, ids=[" ".join(a) for a, _ in BAD])
def test_bad_input_gets_one_line_and_exit_code_2(args, reason, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # an empty folder: `.` holds no chunk files
    r = bench(*args)
    assert r.exit_code == 2, r.output
    lines = [line for line in r.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:"), r.stderr
    assert reason in lines[0]
