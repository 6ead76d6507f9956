"""The HTML report: which failed episodes it shows, its refusals, and the page itself in a
real headless browser (Debian's chromium, which `.ci/run` installs)."""

import importlib.util
import json
import re
import shutil
from dataclasses import asdict

import pytest

from hsgplan.domain.errors import InvalidInputError
from hsgplan.evaluation.config import EvalConfig
from hsgplan.evaluation.episode import EpisodeRecord, StepRecord
from hsgplan.evaluation.protocol import episode_specs
from hsgplan.evaluation.report import _collapsed, build_report, read_summary, sample_failures
from hsgplan.evaluation.summary import summarize
from hsgplan.runner.run_folder import CONFIG, RESULTS

CHROMIUM = shutil.which("chromium")


def _record(seed: int, failure: str | None, status="success", size=2, goal="On(butter, shelf_a)"):
    step = StepRecord(1, "InGrasp(butter)", "pick(butter)", "pick(obj=butter)", status, "", 0, 0, 0)
    return EpisodeRecord(seed, "learned", goal, size, failure is None, 0.5, failure, (step,), 1.0)


def _run_folder(tmp_path, method: str, records: list[EpisodeRecord], config: EvalConfig):
    folder = tmp_path / method
    folder.mkdir(parents=True)
    (folder / CONFIG).write_text(json.dumps(asdict(config) | {"sizes": list(config.sizes)}))
    rows = [
        {"key": f"{r.size}/{k}/{r.seed}/{r.goal}", "result": r.to_json()}
        for k, r in enumerate(records)
    ]
    (folder / RESULTS).write_text("".join(json.dumps(row) + "\n" for row in rows))
    summary = {
        "methods": {
            method: {"agent": config.agent, "wall_seconds": 1.0, "sittings": []}
            | summarize(records)
        },
        "goals": config.goals,
        "goals_file": None,
        "repeats": 1,
        "seed": config.seed,
        "run": str(tmp_path),
    }
    (tmp_path / "summary.json").write_text(json.dumps(summary))


def test_the_sample_takes_each_kind_of_failure_in_turn(tmp_path):
    records = [
        _record(1, "failed_primitive", "no_path"),
        _record(2, "failed_primitive", "no_path"),
        _record(3, "failed_primitive", "no_path"),
        _record(4, "knocked_over"),
        _record(5, None),
        _record(6, "overstep"),
    ]
    _run_folder(tmp_path, "gnn", records, EvalConfig("learned", (2,), 6, 0))
    sample = sample_failures(tmp_path, ["gnn"], 4)
    # the commonest kind first, then one of every other kind, then the commonest again
    assert [r.seed for _, r in sample] == [1, 4, 6, 2]
    assert sample_failures(tmp_path, ["gnn"], 0) == []


def test_refuses_what_is_not_a_finished_eval_run(tmp_path):
    with pytest.raises(InvalidInputError, match="not a folder"):
        read_summary(tmp_path / "missing")
    with pytest.raises(InvalidInputError, match="no run of 'eval world'"):
        read_summary(tmp_path)
    (tmp_path / "summary.json").write_bytes(b"\xff\xfe{")
    with pytest.raises(InvalidInputError, match="not UTF-8"):
        read_summary(tmp_path)
    (tmp_path / "summary.json").write_text("{")
    with pytest.raises(InvalidInputError, match="not valid JSON"):
        read_summary(tmp_path)
    (tmp_path / "summary.json").write_text('{"by_size": {}}')
    with pytest.raises(InvalidInputError, match="no methods"):
        read_summary(tmp_path)


@pytest.mark.parametrize(
    ("kind", "says"),
    [
        ("eval-task", "holds an eval-task run; report makes a page of an 'eval world' run"),
        ("eval-table", "an 'eval world' run not finished (run it again to finish it)"),
    ],
)
def test_a_folder_without_summary_is_told_apart_by_its_kind(tmp_path, kind, says):
    (tmp_path / "config.json").write_text(json.dumps({"kind": kind}))
    with pytest.raises(InvalidInputError, match=re.escape(says)):
        read_summary(tmp_path)


@pytest.mark.parametrize(
    ("marker", "says"),
    [
        ("episode.json", "holds one episode of 'hsgplan demo'"),
        ("trainings.json", "holds the trainings of 'hsgplan train"),
        (None, "holds no run of 'eval world'"),
    ],
)
def test_a_folder_of_another_command_is_named_not_sent_to_finish(tmp_path, marker, says):
    if marker:
        (tmp_path / marker).write_text("{}")
    with pytest.raises(InvalidInputError, match=re.escape(says)) as refused:
        read_summary(tmp_path)
    assert "run it again" not in str(refused.value)


RERUN = importlib.util.find_spec("rerun") is not None


@pytest.mark.slow
@pytest.mark.skipif(CHROMIUM is None, reason="Debian's chromium is not installed here")
def test_the_page_loads_in_a_browser_with_every_image_and_no_console_error(tmp_path):
    from playwright.sync_api import sync_playwright

    config = EvalConfig("learned", (2,), 1, 0)
    spec = episode_specs(config)[0]
    # logged as failed: re-simulated, the page shows the rollout (and says if it ended otherwise)
    _run_folder(tmp_path, "gnn", [_record(spec.seed, "overstep", goal=spec.goal)], config)
    path = build_report(tmp_path, failures=1, recordings=RERUN)
    rollout = tmp_path / "report" / f"gnn-2-{spec.seed}"
    assert (rollout / "episode.gif").exists()
    if RERUN:  # the rollout's 3D recording, named on the page
        assert (rollout / "episode.rrd").stat().st_size > 0
        assert f"report/gnn-2-{spec.seed}/episode.rrd" in path.read_text()
    errors: list[str] = []
    with sync_playwright() as p:
        browser = p.chromium.launch(
            executable_path=CHROMIUM,
            args=["--no-sandbox", "--disable-gpu", "--disable-background-networking"],
        )
        page = browser.new_page()
        page.on("console", lambda m: m.type == "error" and errors.append(m.text))
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.goto(path.as_uri())
        page.wait_for_load_state("load")
        widths = page.eval_on_selector_all("img", "imgs => imgs.map(i => i.naturalWidth)")
        tables = page.locator("table").count()
        heading = page.locator("h1").inner_text()
        browser.close()
    assert errors == []
    # the rollout's GIF and the two scene graphs (no plot: this folder has none)
    assert len(widths) == 3 and all(w > 0 for w in widths), widths
    assert tables == 4 and "Evaluation report" in heading


def test_a_run_of_identical_failed_steps_is_one_row():
    steps = [
        StepRecord(k, "InGrasp(butter)", "pick(butter)", "pick(obj=butter)", status, "", 0, 0, 0)
        for k, status in enumerate(["success", "no_ik", "no_ik", "no_ik"], start=1)
    ]
    rows = _collapsed(steps)
    assert [r[0] for r in rows] == ["1", "2–4 (×3)"] and rows[1][3] == "no_ik"


def test_the_sample_reads_every_training_of_a_method(tmp_path):
    config = EvalConfig("learned", (2,), 2, 0)
    _run_folder(tmp_path, "gnn/seed-0", [_record(1, None)], config)
    _run_folder(tmp_path, "gnn/seed-1", [_record(1, "knocked_over")], config)
    sample = sample_failures(tmp_path, ["gnn"], 4)
    assert [(folder, r.seed) for folder, r in sample] == [("gnn/seed-1", 1)]
