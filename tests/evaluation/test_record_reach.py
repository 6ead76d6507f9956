"""Collecting executed primitives in the simulated world (`hsgplan collect reach`)."""

import json
import random

from typer.testing import CliRunner

from hsgplan.cli import app
from hsgplan.data.world_trials import load_world_trials
from hsgplan.domain.actions import Pick, Place, Push
from hsgplan.domain.world import INTERIOR_CAPACITY, SHELVES, SURFACE_CAPACITY
from hsgplan.evaluation.record_reach import (
    ACTIONS_PER_STATE,
    ReachChunk,
    choose_actions,
    draw_reach_state,
    run_reach_chunk,
)
from tests.agents.test_no_rules_at_inference import RULES, rules_forbidden

# Building a state checks its structure and limits (`domain/feasibility.py`): the drawn states
# are the world's; what the collector may not ask is whether an action applies.
ACTION_RULES = tuple(r for r in RULES if r.name != "feasibility.py")


def test_drawn_states_are_reproducible_and_hold_the_hard_situations():
    states = [draw_reach_state(3, i) for i in range(200)]
    assert states == [draw_reach_state(3, i) for i in range(200)]
    held = sum(s.held() is not None for s in states)
    full_top = sum(
        any(len(s.resting_on(t)) >= c for t, c in SURFACE_CAPACITY.items() if t != "open_space")
        for s in states
    )
    full_inside = sum(
        any(len(s.inside(x)) >= INTERIOR_CAPACITY[x] for x in SHELVES) for s in states
    )
    covered = sum(any(s.resting_on(o) for o in s.objects) for s in states)
    assert min(held, full_top, full_inside, covered) >= 10, (held, full_top, full_inside, covered)


def test_actions_are_distinct_and_of_every_kind_over_states():
    kinds = set()
    for i in range(30):
        state = draw_reach_state(0, i)
        chosen = choose_actions(state, random.Random(i))
        assert len(set(chosen)) == len(chosen) <= ACTIONS_PER_STATE
        kinds |= {type(a) for a in chosen}
    assert kinds == {Pick, Place, Push}


def test_the_world_refuses_a_pick_while_the_hand_is_full_and_no_rule_is_asked():
    calls: list[str] = []
    with rules_forbidden(calls, ACTION_RULES):
        result = run_reach_chunk(ReachChunk(0, 0))
    assert calls == []
    rows = [r for r in result["states"] if r["staged"]]
    assert rows
    full_hand_picks = [
        t
        for r in rows
        for t in r["trials"]
        if any(lit.startswith("InGrasp") for lit in r["state"]) and t["action"].startswith("pick")
    ]
    assert full_hand_picks and all(t["status"] != "success" for t in full_hand_picks)


def test_collect_reach_runs_resumes_and_refuses_bad_counts(tmp_path):
    out = tmp_path / "reach"
    args = ["collect", "reach", "--states", "8", "--workers", "1", "--out", str(out)]
    r = CliRunner().invoke(app, args)
    assert r.exit_code == 0, r.output
    lines = (out / "episodes.jsonl").read_text().splitlines()
    trials = load_world_trials(out)
    assert len(lines) == 1 and len(trials) > 0
    r = CliRunner().invoke(app, args)
    assert r.exit_code == 0 and (out / "episodes.jsonl").read_text().splitlines() == lines
    assert json.loads(lines[0])["key"] == "0/0"
    r = CliRunner().invoke(app, ["collect", "reach", "--states", "-1", "--out", str(out)])
    assert r.exit_code == 2 and "at least one" in r.stderr
