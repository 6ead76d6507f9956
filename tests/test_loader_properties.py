"""Property tests of everything that reads outside input: goal files, training configurations,
run folders and checkpoints. Whatever the bytes, the answer is a value or one line of refusal
(InvalidInputError), never another exception."""

import json
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from hsgplan.checkpoint import load_trained
from hsgplan.domain.checks import read_json
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.goals import read_goal_file
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.motion.train import MotionTrainConfig
from hsgplan.planning.regression.train import TaskTrainConfig
from hsgplan.runner.run_folder import claim, logged_rows

SETTINGS = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
GOAL_LINES = st.sampled_from(
    ["On(butter, shelf_a)", "In(cherries, shelf_a) & Clear(popcorn)", "# a comment", "", "On("]
)
ENCODINGS = st.sampled_from(["utf-8", "utf-8-sig", "utf-16", "latin-1"])
JSON_VALUES = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=8),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=6), inner),
    max_leaves=8,
)


def _one_line(e: InvalidInputError) -> None:
    assert str(e) and "\n" not in str(e)


SCRATCH = tempfile.TemporaryDirectory()  # one for the module: examples reuse it, then it goes


def _folder() -> Path:
    return Path(tempfile.mkdtemp(dir=SCRATCH.name))


def _file(data: bytes) -> Path:
    (path := _folder() / "f").write_bytes(data)
    return path


@SETTINGS
@given(st.lists(GOAL_LINES | st.text(max_size=20), max_size=6), ENCODINGS, st.binary(max_size=8))
def test_a_goal_file_is_goals_or_one_refusal(lines, encoding, junk):
    text = "\n".join(lines)
    try:
        data = text.encode(encoding) + junk
    except UnicodeEncodeError:
        data = junk
    try:
        goals = read_goal_file(_file(data), world=KITCHEN)
    except InvalidInputError as e:
        _one_line(e)
    else:
        assert goals and all(g.literals for g in goals)


@SETTINGS
@given(
    st.dictionaries(
        st.sampled_from(
            ["lr", "seed", "epochs", "hidden", "batch_size", "copies", "vary", "rounds", "x"]
        ),
        JSON_VALUES,
        max_size=4,
    )
)
def test_a_training_configuration_is_checked_or_one_refusal(settings_):
    for cls in (TaskTrainConfig, MotionTrainConfig):
        try:
            config = cls.from_json(settings_)
        except InvalidInputError as e:
            _one_line(e)
        else:  # what is accepted holds to its bounds and reads back as itself
            assert config.lr > 0 and 0 <= config.seed < 2**32 and config.epochs >= 1
            assert cls.from_json(json.loads(json.dumps(config.__dict__))) == config


@SETTINGS
@given(st.binary(max_size=200) | JSON_VALUES.map(lambda v: json.dumps(v).encode()))
def test_any_config_file_is_read_or_refused_in_one_line(data):
    try:
        value = read_json(_file(data), "--config")
    except InvalidInputError as e:
        _one_line(e)
    else:
        assert isinstance(value, dict)


@SETTINGS
@given(
    st.lists(
        st.binary(max_size=30)
        | JSON_VALUES.map(json.dumps).map(str.encode)
        | st.just(b'{"key": "a", "result": 1}'),
        max_size=6,
    ),
    st.binary(max_size=60) | JSON_VALUES.map(lambda v: json.dumps(v).encode()),
)
def test_a_run_folder_is_read_back_or_refused_in_one_line(log_lines, config):
    folder = _folder()
    (folder / "episodes.jsonl").write_bytes(b"\n".join(log_lines))
    rows = logged_rows(folder)  # a damaged line is skipped (its item runs again), never fatal
    assert all(isinstance(r, dict | list | str | int | float | bool | None) for r in rows)
    after = (folder / "episodes.jsonl").read_bytes()
    assert after.endswith(b"\n") or not after  # the next row starts on a line of its own
    (folder / "config.json").write_bytes(config)
    try:
        claim(folder, "eval", {"a": 1}, "another configuration")
    except InvalidInputError as e:
        _one_line(e)
    else:
        assert json.loads((folder / "config.json").read_text()) == {"kind": "eval", "a": 1}


@SETTINGS
@given(st.binary(max_size=100), st.binary(max_size=100), st.binary(max_size=100))
def test_any_checkpoint_folder_is_loaded_or_refused_in_one_line(weights, config, manifest):
    import torch

    folder = _folder()
    for name, data in (("model.safetensors", weights), ("config.json", config)):
        (folder / name).write_bytes(data)
    (folder / "manifest.json").write_bytes(manifest)
    with pytest.raises(InvalidInputError) as e:
        load_trained(folder, lambda d: d, lambda c: torch.nn.Linear(2, 2), "network")
    _one_line(e.value)
