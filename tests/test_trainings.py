"""One configuration trained several times (a folder per seed), and intervals over trainings,
goals and repeats."""

import json
import random

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from hsgplan.cli import app
from hsgplan.domain.errors import InvalidInputError
from hsgplan.evaluation.config import EvalConfig
from hsgplan.evaluation.intervals import goal_interval, separate, training_goal_interval
from hsgplan.evaluation.protocol import trained, training_dir
from hsgplan.trainings import RECORD, paired, record, seed_folders

TINY_MOTION = {"epochs": 1, "samples": 64, "hidden": 16, "embed": 8, "rounds": 1, "loss": "ce"}


def _trainings(root, seeds):
    for s in seeds:
        (root / f"seed-{s}").mkdir(parents=True)
    record(root, list(seeds), "task")
    return root


def test_a_trainings_folder_is_known_by_its_record(tmp_path):
    root = _trainings(tmp_path / "t", [0, 1, 2])
    assert list(seed_folders(root)) == [0, 1, 2]
    (root / RECORD).unlink()
    assert seed_folders(root) is None  # seed-S folders alone are no trainings folder
    assert seed_folders(None) is None


def test_trainings_pair_by_seed_and_a_plain_folder_serves_every_seed(tmp_path):
    task = _trainings(tmp_path / "task", [0, 1])
    motion = _trainings(tmp_path / "motion", [0, 1])
    assert paired(task, motion)[1] == (str(task / "seed-1"), str(motion / "seed-1"))
    assert paired(task, "plain")[0] == (str(task / "seed-0"), "plain")
    assert paired("a", "b") == {None: ("a", "b")}
    other = _trainings(tmp_path / "other", [5, 6])
    with pytest.raises(InvalidInputError, match="same seeds"):
        paired(task, other)


def test_an_evaluation_runs_each_training_in_a_folder_of_its_own(tmp_path):
    task = _trainings(tmp_path / "task", [3, 4])
    config = EvalConfig("learned", (3,), 2, 0, checkpoint=str(task))
    runs = trained(config)
    assert list(runs) == [3, 4] and runs[4].checkpoint == str(task / "seed-4")
    assert training_dir(tmp_path / "gnn", 4) == tmp_path / "gnn" / "seed-4"
    assert trained(EvalConfig("learned", (3,), 2, 0)) == {None: EvalConfig("learned", (3,), 2, 0)}


def test_train_motion_seeds_trains_each_seed_into_its_folder(tmp_path):
    config = tmp_path / "tiny.json"
    config.write_text(json.dumps(TINY_MOTION))
    out = tmp_path / "motion"
    args = ["train", "motion", "--config", str(config), "--seeds", "2", "--out", str(out)]
    r = CliRunner().invoke(app, args)
    assert r.exit_code == 0, r.output
    weights = [(out / f"seed-{s}" / "place-gnn" / "model.safetensors").read_bytes() for s in (0, 1)]
    assert weights[0] != weights[1]  # another seed, another network
    saved = [
        json.loads((out / f"seed-{s}" / "place-gnn" / "config.json").read_text()) for s in (0, 1)
    ]
    assert [c.get("seed") for c in saved] in ([0, 1], [None, None])
    assert json.loads((out / RECORD).read_text()) == {
        "trained": {"place-gnn": [0, 1]},
        "shipped_seed": 0,
    }
    assert list(seed_folders(out)) == [0, 1]
    bad = CliRunner().invoke(app, [*args[:-2], "--out", str(out), "--name", "../x"])
    assert bad.exit_code == 2
    # side by side, each training in a process of its own: the same networks
    side = CliRunner().invoke(app, [*args[:-2], "--out", str(tmp_path / "side"), "--workers", "2"])
    assert side.exit_code == 0, side.output
    again = [
        (tmp_path / "side" / f"seed-{s}" / "place-gnn" / "model.safetensors").read_bytes()
        for s in (0, 1)
    ]
    assert again == weights


def test_several_configurations_train_in_one_pool_as_each_alone(tmp_path):
    configs = []
    for model in ("gnn", "mlp"):
        configs.append(tmp_path / f"{model}.json")
        configs[-1].write_text(json.dumps(TINY_MOTION | {"model": model}))
    out = tmp_path / "both"
    args = ["train", "motion", "--config", str(configs[0]), "--config", str(configs[1])]
    r = CliRunner().invoke(app, [*args, "--seeds", "2", "--workers", "2", "--out", str(out)])
    assert r.exit_code == 0, r.output
    assert json.loads((out / RECORD).read_text())["trained"] == {
        "place-gnn": [0, 1],
        "place-mlp": [0, 1],
    }
    alone = tmp_path / "alone"
    r = CliRunner().invoke(app, [*args[:4], "--seeds", "2", "--out", str(alone)])
    assert r.exit_code == 0, r.output
    for s in (0, 1):
        weights = [f / f"seed-{s}" / "place-gnn" / "model.safetensors" for f in (out, alone)]
        assert weights[0].read_bytes() == weights[1].read_bytes()
    # several configurations name their networks themselves, and only with --seeds
    for extra in (["--seeds", "2", "--name", "x"], []):
        r = CliRunner().invoke(app, [*args, *extra, "--out", str(tmp_path / "bad")])
        assert r.exit_code == 2 and "several --config" in r.stderr
    r = CliRunner().invoke(app, [*args[:4], *args[2:4], "--seeds", "1", "--out", str(out)])
    assert r.exit_code == 2 and "the same network" in r.stderr


def test_an_interval_needs_two_goals():
    assert goal_interval({"a": [1.0, 0.0, 1.0]}) is None
    assert goal_interval({"a": [1.0, 1.0], "b": [1.0]}) == (1.0, 1.0)
    low, high = goal_interval({"a": [1.0], "b": [0.0]})
    assert low == 0.0 and high == 1.0


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 10_000), st.integers(2, 5))
def test_an_interval_holds_its_mean_and_is_the_same_every_time(seed, runs):
    rng = random.Random(seed)
    strata = {str(g): [float(rng.random() < 0.7) for _ in range(runs)] for g in range(30)}
    low, high = goal_interval(strata)
    mean = sum(sum(v) / len(v) for v in strata.values()) / len(strata)
    assert low - 1e-9 <= mean <= high + 1e-9
    assert goal_interval(strata) == (low, high)


def test_an_interval_is_as_wide_as_goals_differ_and_each_goal_counts_once():
    # goals that differ from one another widen it; how many episodes a goal had does not
    # weigh it more: a goal is the unit drawn
    alike = {str(g): [1.0, 0.0] for g in range(40)}
    differ = {str(g): [1.0, 1.0] if g % 2 else [0.0, 0.0] for g in range(40)}
    assert goal_interval(alike) == (0.5, 0.5)
    low, high = goal_interval(differ)
    assert low < 0.5 < high
    heavy = differ | {"0": [0.0] * 50}
    assert goal_interval(heavy) == (low, high)


def _cells(rates, goals=40):
    """Each training's episodes of each goal: training t wins goal g when g falls under its
    rate, so trainings of different rates disagree on the same goals."""
    return {(t, g): [float(g < rate * goals)] for t, rate in enumerate(rates) for g in range(goals)}


def _width(interval):
    return interval[1] - interval[0]


def test_an_interval_over_trainings_is_as_wide_as_trainings_differ():
    # the same episodes, pooled per goal as if one training ran them, give the interval over
    # goals alone; trainings that disagree must widen it, trainings that agree must not
    differ = _cells([0.9, 0.3, 0.9])
    pooled = {g: [v[0] for (_, h), v in differ.items() if h == g] for g in range(40)}
    assert _width(training_goal_interval(differ)) > 1.5 * _width(goal_interval(pooled))
    agree = _cells([0.7, 0.7, 0.7])
    alone = {g: v for (t, g), v in agree.items() if t == 0}
    assert _width(training_goal_interval(agree)) == pytest.approx(
        _width(goal_interval(alone)), abs=0.05
    )
    mean = sum(v[0] for v in differ.values()) / len(differ)
    low, high = training_goal_interval(differ)
    assert low <= mean <= high


def test_an_interval_over_one_training_is_over_goals():
    cells = _cells([0.6])
    alone = {g: v for (_, g), v in cells.items()}
    assert training_goal_interval(cells) == goal_interval(alone)
    assert training_goal_interval({(0, "a"): [1.0], (1, "a"): [0.0]}) is None


def test_a_summary_of_trainings_draws_trainings_too():
    from hsgplan.evaluation.episode import EpisodeRecord
    from hsgplan.evaluation.summary import summarize_trainings

    def episode(goal, won):
        failure = None if won else "overstep"
        return EpisodeRecord(goal, "learned", f"goal-{goal}", 2, won, 1.0, failure, (), 1.0)

    def run(rate):
        return [episode(g, g < rate * 40) for g in range(40)]

    one = summarize_trainings({None: run(0.6)})["by_size"]["2"]["success_ci"]
    three = summarize_trainings({0: run(0.9), 1: run(0.3), 2: run(0.6)})["by_size"]["2"]
    assert three["success_by_training"] == [0.9, 0.3, 0.6]
    assert three["success_rate"] == pytest.approx(0.6)
    assert _width(three["success_ci"]) > 1.5 * _width(one)


def test_a_gain_is_called_only_where_intervals_separate():
    assert separate((0.5, 0.6), (0.65, 0.7)) and separate((0.65, 0.7), (0.5, 0.6))
    assert not separate((0.5, 0.66), (0.65, 0.7))
    assert not separate(None, (0.1, 0.2))


@pytest.mark.slow
def test_a_table_runs_every_training_and_reports_over_them(tmp_path):
    import shutil

    from hsgplan.evaluation.table1 import Method, run_table, tables
    from hsgplan.paths import TASK_CHECKPOINT

    task = tmp_path / "task"
    for s in (0, 1):
        shutil.copytree(TASK_CHECKPOINT, task / f"seed-{s}")
    record(task, [0, 1], "task")
    config = EvalConfig(
        "", (2,), 2, 2_000_000, checkpoint=str(task), protocol="paper", split="test"
    )
    report = run_table([Method("gnn", "learned")], config, tmp_path / "run", workers=1)
    gnn = report["methods"]["gnn"]
    assert gnn["trainings"] == [0, 1] and gnn["by_size"]["2"]["episodes"] == 4
    assert len(gnn["by_size"]["2"]["success_by_training"]) == 2
    assert gnn["by_size"]["2"]["success_ci"] is not None  # each goal run under both trainings
    assert {p.name for p in (tmp_path / "run" / "gnn").iterdir()} == {"seed-0", "seed-1"}
    title = tables(report, ("success",))[0].title
    assert "under each of 2 trainings" in title and "test split" in title


def test_a_regularised_mlp_trains_and_its_network_reads_back_with_its_dropout(tmp_path):
    from hsgplan.motion.models import load_motion_net
    from hsgplan.motion.train import MotionTrainConfig, train_motion

    settings = {**TINY_MOTION, "model": "mlp", "dropout": 0.3, "weight_decay": 0.01}
    train_motion(MotionTrainConfig.from_json(settings), tmp_path / "mlp")
    net = load_motion_net(tmp_path / "mlp", "place", "mlp")
    assert net.config.dropout == 0.3 and not net.training
    saved = json.loads((tmp_path / "mlp" / "train_config.json").read_text())
    assert saved["weight_decay"] == 0.01
