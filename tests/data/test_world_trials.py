"""The format of executed primitives (`data/world_trials.py`): round trip and damaged files."""

import json

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hsgplan.data.world_trials import load_world_trials, state_json, trials_of
from hsgplan.domain.errors import InvalidInputError
from hsgplan.evaluation.record_reach import draw_reach_state


def _row(state, action="pick(cherries)", status="invalid", after=None):
    return {
        "staged": True,
        "objects": list(state.objects),
        "state": state_json(state),
        "trials": [{"action": action, "status": status, "after": after}],
    }


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 10_000))
def test_a_logged_state_reads_back_as_it_was(index):
    state = draw_reach_state(0, index)
    row = json.loads(json.dumps(_row(state, after=state_json(state))))
    (trial,) = trials_of(row)
    assert trial.state == state and trial.after == state
    assert str(trial.action) == "pick(cherries)" and not trial.succeeded


def test_a_collection_folder_reads_in_key_order(tmp_path):
    a, b = draw_reach_state(0, 1), draw_reach_state(0, 2)
    lines = [
        {"key": "0/10", "result": {"states": [_row(b)]}},
        {"key": "0/2", "result": {"states": [_row(a), {"staged": False}]}},
    ]
    text = "\n".join(json.dumps(x) for x in lines) + "\n" + '{"key": "0/3", "res'
    (tmp_path / "episodes.jsonl").write_text(text)
    trials = load_world_trials(tmp_path)
    assert [t.state for t in trials] == [a, b]  # 2 before 10; the cut line is left out


def test_missing_and_damaged_collections_are_refused(tmp_path):
    with pytest.raises(InvalidInputError, match="no collection"):
        load_world_trials(tmp_path)
    (tmp_path / "episodes.jsonl").write_text('{"key": "0/0", "result": {"states": [{}]}}\n')
    assert load_world_trials(tmp_path) == []  # a state not staged
    (tmp_path / "episodes.jsonl").write_text('{"key": "0/0", "result": {"stat": 1}}\n')
    with pytest.raises(InvalidInputError, match="damaged"):
        load_world_trials(tmp_path)
    (tmp_path / "episodes.jsonl").write_bytes("{\"key\": \"é\"}".encode("latin-1") + b"}")
    with pytest.raises(InvalidInputError, match="damaged"):
        load_world_trials(tmp_path)
