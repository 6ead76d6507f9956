"""`hsgplan labels`: every source of the shipped networks' labels with its counts, and the
hand-written rule among them named where it is."""

from typer.testing import CliRunner

from hsgplan.cli import app
from hsgplan.evaluation.labels import WHO, label_rows
from hsgplan.paths import MOTION_CHECKPOINTS, TASK_CHECKPOINT


def test_the_shipped_task_networks_name_every_source_and_the_rule_inside_the_copies():
    rows = label_rows(TASK_CHECKPOINT)
    assert {r.who for r in rows} <= set(WHO.values())  # no source left unexplained
    copies = [r for r in rows if r.source == "copies with added objects"]
    assert copies and all("hand-written rule" in r.who for r in copies)
    assert all(r.labels >= r.examples > 0 for r in rows)


def test_a_motion_network_counts_the_trials_it_learned_from(tmp_path):
    (row,) = label_rows(MOTION_CHECKPOINTS / "place-gnn")
    assert row.examples > 0 and "held out" in row.source
    r = CliRunner().invoke(app, ["labels", str(tmp_path)])
    assert r.exit_code == 2 and "no task checkpoint" in r.stderr
