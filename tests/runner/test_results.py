"""`hsgplan results`: the plan's steps run in order, a finished one skipped while its command is
unchanged, and its table pasted stamped with its command and commit."""

import json
import shlex
from pathlib import Path

import pytest

from hsgplan.domain.errors import InvalidInputError
from hsgplan.runner import results
from hsgplan.runner.results import Step, chosen, finished, paste, read_plan, run_plan

ROOT = Path(__file__).resolve().parents[2]


def test_the_shipped_plan_names_configs_that_exist_and_tables_a_page_holds():
    steps = read_plan(ROOT / results.PLAN)
    pages = "".join(p.read_text() for p in [ROOT / "README.md", *(ROOT / "docs").glob("*.md")])
    for s in steps:
        args = shlex.split(s.command)
        for option, value in zip(args, args[1:], strict=False):
            if option == "--config":
                assert (ROOT / value).is_file(), (s.name, value)
        if s.block:
            assert f"<!-- BEGIN {s.block} -->" in pages, s.block
        if args[:2] in (["eval", "world"], ["eval", "motion"], ["bench", "timing"]):
            assert "--split test" in s.command, s.name  # a published table is the test split's
    assert [s.name for s in chosen(steps, skip=["slow"])] == [
        s.name for s in steps if "slow" not in s.tags
    ]


def test_the_tune_plan_names_configs_that_exist_and_draws_only_from_the_tune_split():
    steps = read_plan(ROOT / "configs/tune/plan.toml")
    published = {s.name for s in read_plan(ROOT / results.PLAN)}
    for s in steps:
        assert s.name not in published, s.name  # the stamps share runs/results/steps/
        args = shlex.split(s.command)
        for option, value in zip(args, args[1:], strict=False):
            if option == "--config":
                assert (ROOT / value).is_file(), (s.name, value)
        if args[0] == "eval" and args[1] != "compare":  # a comparison reads finished runs
            assert "--split tune" in s.command, s.name  # choosing never reads the test split


def test_only_and_skip_choose_steps_and_refuse_unknown_names():
    steps = [Step("a", "x"), Step("b", "y", tags=("slow",)), Step("c", "z")]
    assert [s.name for s in chosen(steps, only=["a", "b"], skip=["slow"])] == ["a"]
    assert [s.name for s in chosen(steps, only=["slow", "c"])] == ["b", "c"]  # a tag, a name
    with pytest.raises(InvalidInputError, match="no step or tag 'd'"):
        chosen(steps, skip=["d"])


def test_a_plan_without_names_is_refused_in_one_line(tmp_path):
    plan = tmp_path / "plan.toml"
    plan.write_text('[[step]]\ncommand = "splits show"\n')
    with pytest.raises(InvalidInputError, match="needs a name"):
        read_plan(plan)


def test_a_finished_step_is_skipped_until_its_command_changes(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(results, "commit", lambda: "abc123")
    step = Step("show", "splits show --markdown", block="splits-table")
    lines: list[str] = []
    run_plan([step], tmp_path / "out", echo=lines.append)
    made = finished(tmp_path / "out", step)
    assert made["commit"] == "abc123" and made["command"] == step.command
    assert "| test |" in (tmp_path / "out" / "blocks" / "splits-table.md").read_text()
    run_plan([step], tmp_path / "out", echo=lines.append)
    assert lines[-1].startswith("show: finished at abc123")
    assert finished(tmp_path / "out", Step("show", "splits show")) is None  # another command


def test_a_failed_step_stops_the_pass_and_leaves_no_record(tmp_path):
    bad = Step("bad", "eval world --split nowhere")
    with pytest.raises(InvalidInputError, match="step 'bad' failed"):
        run_plan([bad, Step("after", "splits show")], tmp_path, echo=lambda _: None)
    assert not (tmp_path / "steps").exists()


def test_paste_stamps_each_block_with_its_command_and_commit(tmp_path):
    blocks = tmp_path / "out" / "blocks"
    blocks.mkdir(parents=True)
    (blocks / "t.md").write_text("| a |\n|---:|\n| 1 |\n")
    made = {"command": "eval world --split test", "commit": "abc123", "date": "d", "machine": "m"}
    (blocks / "t.json").write_text(json.dumps(made))
    page = tmp_path / "README.md"
    page.write_text("x\n<!-- BEGIN t -->\nold\n<!-- END t -->\ny\n")
    assert paste([page], tmp_path / "out") == ["t"]
    text = page.read_text()
    assert "old" not in text and "| 1 |" in text
    assert "`hsgplan eval world --split test`) at commit abc123" in text
    page.write_text("no blocks here\n")
    with pytest.raises(InvalidInputError, match="no page holds a block named 't'"):
        paste([page], tmp_path / "out")


def _folder(path: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        (path / name).parent.mkdir(parents=True, exist_ok=True)
        (path / name).write_text(text)
    return path


def test_ship_copies_the_made_files_and_renames_the_paths_inside_them(tmp_path):
    from hsgplan.runner.ship import Shipment, ship

    config = {"data": "runs/r/motion", "loop_trials": "runs/r/task-staged/x", "seed": 0}
    _folder(
        tmp_path / "runs/r/nets/seed-0/place-gnn",
        {"train_config.json": json.dumps(config), "manifest.json": '{"data": "runs/r/motion"}'},
    )
    _folder(
        tmp_path / "runs/r/motion",
        {"place.npz": "x", "work/chunk-0.npz": "c", ".lock": "l", "timing.json": "{}"},
    )
    _folder(tmp_path / "data/motion", {"old.npz": "old"})
    moves = [
        Shipment("runs/r/motion", "data/motion"),
        Shipment("runs/r/nets/seed-0/place-gnn", "checkpoints/motion/place-gnn"),
        Shipment("runs/r/task-staged", "checkpoints/task-staged"),
    ]
    with pytest.raises(InvalidInputError, match="finish the pass first"):
        ship(moves, tmp_path)  # task-staged is not there: nothing is copied
    assert (tmp_path / "data/motion/old.npz").exists()
    _folder(tmp_path / "runs/r/task-staged", {"x": "x"})
    assert ship(moves, tmp_path)[:2] == ["data/motion", "checkpoints/motion/place-gnn"]
    assert sorted(p.name for p in (tmp_path / "data/motion").iterdir()) == ["place.npz"]
    net = tmp_path / "checkpoints/motion/place-gnn"
    shipped = json.loads((net / "train_config.json").read_text())
    assert shipped == {"data": "data/motion", "loop_trials": "checkpoints/task-staged/x", "seed": 0}
    assert json.loads((net / "manifest.json").read_text()) == {"data": "runs/r/motion"}  # as is
    assert not list(tmp_path.rglob("*.shipping")) and not list(tmp_path.rglob("*.old"))
    # a partial shipment names where the rest will live
    _folder(tmp_path / "runs/r/nets/seed-0/place-gnn", {"train_config.json": json.dumps(config)})
    assert ship(moves[1:2], tmp_path, renames=moves) == ["checkpoints/motion/place-gnn"]
    assert json.loads((net / "train_config.json").read_text())["data"] == "data/motion"


def test_a_shipment_waits_for_every_step_that_writes_into_it():
    steps = [
        results.Step("a", "collect place --out runs/r/motion"),
        results.Step("b", "collect push --out runs/r/motion"),
        results.Step("c", "train motion --name p --out runs/r/nets"),
        results.Step("d", "train task --out runs/r/nets-other"),
    ]
    assert [s.name for s in results.writers(steps, "runs/r/motion")] == ["a", "b"]
    assert [s.name for s in results.writers(steps, "runs/r/nets/seed-0/p")] == ["c"]
    assert results.writers(steps, "runs/r/net") == []


def test_the_shipped_plan_ships_what_its_steps_make():
    from hsgplan.runner.ship import read_shipments

    steps = read_plan(ROOT / results.PLAN)
    outs = [
        a
        for s in steps
        for o, a in zip(shlex.split(s.command), shlex.split(s.command)[1:], strict=False)
        if o == "--out"
    ]
    for m in read_shipments(ROOT / results.PLAN):
        assert any(m.source == o or m.source.startswith(o + "/") for o in outs), m.source
        assert results.writers(steps, m.source)  # a shipment waits for the steps that make it
        assert m.destination.split("/")[0] in ("data", "checkpoints")


def test_a_finished_steps_picture_is_copied_where_its_page_shows_it(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "runs/r").mkdir(parents=True)
    (tmp_path / "runs/r/t.png").write_bytes(b"png")
    plan = tmp_path / "plan.toml"
    plan.write_text(
        '[[step]]\nname = "t"\ncommand = "eval world"\npicture = ["runs/r/t.png", "docs/t.png"]\n'
    )
    (step,) = read_plan(plan)
    out = tmp_path / "runs/results"
    assert results.copy_pictures([step], out) == []  # not finished: nothing copied
    (out / "steps").mkdir(parents=True)
    (out / "steps/t.json").write_text(json.dumps({"command": "eval world"}))
    assert results.copy_pictures([step], out) == ["docs/t.png"]
    assert (tmp_path / "docs/t.png").read_bytes() == b"png"
    plan.write_text('[[step]]\nname = "t"\ncommand = "x"\npicture = "one.png"\n')
    with pytest.raises(InvalidInputError, match="picture"):
        read_plan(plan)
