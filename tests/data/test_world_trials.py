"""The format of primitives executed in the world (`data/world_trials.py`): rows read back as
written, collections in key order, damaged ones refused in one line."""

import json

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hsgplan.collect.reach import draw_reach_state
from hsgplan.data.world_trials import (
    UNSTAGED,
    WorldTrial,
    load_world_trials,
    read_state,
    state_json,
    state_row,
    trials_of,
)
from hsgplan.domain.actions import parse_action
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.predicates import Predicate, on
from hsgplan.planning.heuristic import action_for, candidate_literals
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.sim.outcome import Status

STATUSES = [s.value for s in Status] + ["no_parameters"]


def _moved(state: SymbolicSceneGraph, obj: str) -> SymbolicSceneGraph:
    """The state with `obj` on the open space: what a place or a stray push may leave."""
    rest = [
        lit for lit in state.literals if lit.subject != obj and lit.predicate is not Predicate.CLEAR
    ]
    return SymbolicSceneGraph.from_literals(
        state.objects, [*rest, on(obj, "open_space")], False, world=KITCHEN
    )


@st.composite
def rows(draw):
    state = draw_reach_state(draw(st.integers(0, 3)), draw(st.integers(0, 10_000)), KITCHEN)
    actions = sorted({action_for(lit, state) for lit in candidate_literals(state)}, key=str)
    trials = []
    for _ in range(draw(st.integers(0, 4))):
        after = draw(
            st.sampled_from([None, state])
            | st.sampled_from(state.objects).map(lambda o, s=state: _moved(s, o))
        )
        trials.append(
            WorldTrial(
                state, draw(st.sampled_from(actions)), draw(st.sampled_from(STATUSES)), after
            )
        )
    return state, trials


@settings(max_examples=60, deadline=None)
@given(rows())
def test_a_row_reads_back_as_it_was_written(row):
    state, trials = row
    written = json.loads(json.dumps(state_row(state, trials)))
    assert set(written) == {"objects", "state", "trials"}
    assert trials_of(written, world=KITCHEN) == trials
    assert read_state(written["objects"], written["state"], world=KITCHEN) == state


def test_a_row_holds_the_trials_of_its_own_state_only():
    a, b = draw_reach_state(0, 1, KITCHEN), draw_reach_state(0, 2, KITCHEN)
    with pytest.raises(ValueError):
        state_row(a, [WorldTrial(b, parse_action("pick(cherries)", world=KITCHEN), "invalid", b)])
    trial = WorldTrial(a, parse_action("pick(cherries)", world=KITCHEN), "success", None)
    assert not trial.succeeded  # the world toppled something: no clean state to read
    assert WorldTrial(a, trial.action, "success", a).succeeded


def _row(state, status="invalid"):
    return state_row(
        state, [WorldTrial(state, parse_action("pick(cherries)", world=KITCHEN), status, state)]
    )


def _write(folder, lines):
    (folder / "config.json").write_text('{"kind": "reach"}\n')
    (folder / "episodes.jsonl").write_text("".join(x + "\n" for x in lines))


def test_a_collection_reads_in_key_order_past_cut_lines_and_unstaged_states(tmp_path):
    a, b, c = (draw_reach_state(0, i, KITCHEN) for i in range(3))
    _write(
        tmp_path,
        [
            json.dumps({"key": "0/10", "result": _row(b)}),
            '{"key": "0/3", "result": {"objects": ["cherr',  # cut by an interruption, resumed
            json.dumps({"key": "0/2", "result": _row(a)}),
            json.dumps({"key": "0/3", "result": UNSTAGED}),
            json.dumps({"key": "1/0", "result": _row(c)}),
        ],
    )
    assert [t.state for t in load_world_trials(tmp_path, world=KITCHEN)] == [a, b, c]  # 2 before 10


@pytest.mark.parametrize(
    ("line", "match"),
    [
        ('{"key": "0/0", "result": {"objects": []}}', "state 0/0 is damaged: missing 'state'"),
        ('{"key": "0/0"}', "line 1 is damaged: missing 'result'"),
        ('{"key": "zero", "result": {}}', "line 1 is damaged"),
        ('["0/0", {}]', "line 1 is damaged"),
        ('{"key": "0/0", "result": [1]}', "state 0/0 is damaged"),
        (
            '{"key": "0/0", "result": {"objects": ["cherries"], "state": ["Under(cherries)"], '
            '"trials": []}}',
            "state 0/0 is damaged",
        ),
    ],
)
def test_a_damaged_collection_is_refused_in_one_line(tmp_path, line, match):
    _write(tmp_path, [line])
    with pytest.raises(InvalidInputError, match=match) as e:
        load_world_trials(tmp_path, world=KITCHEN)
    assert "\n" not in str(e.value)


def test_a_missing_or_unreadable_collection_is_refused(tmp_path):
    with pytest.raises(InvalidInputError, match="holds no collection"):
        load_world_trials(tmp_path / "nowhere", world=KITCHEN)
    (tmp_path / "episodes.jsonl").write_bytes('{"key": "é"}\n'.encode("latin-1"))
    with pytest.raises(InvalidInputError, match="config.json' does not exist"):
        load_world_trials(tmp_path, world=KITCHEN)  # a folder that is no collection
    (tmp_path / "config.json").write_text('{"kind": "eval"}')
    with pytest.raises(InvalidInputError, match="not a collection of executed primitives"):
        load_world_trials(tmp_path, world=KITCHEN)
    (tmp_path / "config.json").write_text('{"kind": "reach"}')
    with pytest.raises(InvalidInputError, match="not UTF-8"):
        load_world_trials(tmp_path, world=KITCHEN)


def test_state_json_lists_placements_only():
    state = draw_reach_state(0, 5, KITCHEN)
    assert all(not x.startswith("Clear") for x in state_json(state))
    assert read_state(state.objects, state_json(state), world=KITCHEN) == state
