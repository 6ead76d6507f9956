"""The two protocols: a failed primitive ends a paper-protocol episode, and a recovering one
goes on; the recovery rules are named, refused when unknown, and none under the paper's."""

from __future__ import annotations

from dataclasses import replace

import pytest

from hsgplan.agents.base import Decision
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.parameters import PickParams
from hsgplan.domain.recovery import (
    CHECKING_RULES,
    NO_FAILURE_RULES,
    PERCEPTION_RULES,
    RecoveryRules,
)
from hsgplan.evaluation.config import EvalConfig
from hsgplan.evaluation.episode import run_episode
from hsgplan.evaluation.protocol import run_config
from hsgplan.evaluation.summary import EXECUTION, OVERSTEP, failure_class
from hsgplan.sim.env import KitchenStorageEnv

GOAL = parse_goal("On(butter, shelf_a) & On(popcorn, shelf_b)", world=KITCHEN)


class PicksAbsentObject:
    """An agent whose every decision is a primitive that fails: it picks an object that is not
    in the scene, and the world refuses it (nothing moves)."""

    name = "fails"

    def reset(self, goal, seed):
        self.decisions = 0

    def decide(self, sg, state, goal, feasible=None):
        self.decisions += 1
        return Decision(None, PickParams("cherries"), 0.0, 0.0)

    def observe(self, params, outcome):
        pass


def test_a_failed_primitive_ends_a_paper_protocol_episode():
    agent = PicksAbsentObject()
    record = run_episode(KitchenStorageEnv(world=KITCHEN), agent, GOAL, seed=3, end_at_failure=True)
    assert len(record.steps) == 1 and record.steps[0].status != "success"
    assert record.failure == "failed_primitive" and not record.success
    assert failure_class(record) == (EXECUTION, record.steps[0].status)


def test_a_recovering_episode_out_of_steps_after_failures_is_overstep():
    env = KitchenStorageEnv(max_steps=4, world=KITCHEN)
    record = run_episode(env, PicksAbsentObject(), GOAL, seed=3)
    assert len(record.steps) == 4 and all(s.status != "success" for s in record.steps)
    assert record.failure == "overstep"
    assert failure_class(record) == (OVERSTEP, "step limit")


def test_the_paper_protocol_runs_without_any_recovery_rule_but_those_of_no_failure():
    paper = EvalConfig("learned", (2,), 1, 0, protocol="paper").rules()
    assert paper.off() == tuple(r for r in RecoveryRules.names() if r not in NO_FAILURE_RULES)
    assert set(PERCEPTION_RULES) < set(NO_FAILURE_RULES)
    blind = EvalConfig("learned", (2,), 1, 0, protocol="paper", rules_off=NO_FAILURE_RULES)
    assert blind.rules() == RecoveryRules.none()
    assert EvalConfig("learned", (2,), 1, 0).protocol == "paper"  # every headline's
    recovering = EvalConfig("learned", (2,), 1, 0, protocol="recovering")
    assert recovering.rules() == RecoveryRules()
    some = replace(recovering, rules_off=("push_give_up", "least_taken"))
    assert some.rules().off() == ("push_give_up", "least_taken")
    with pytest.raises(InvalidInputError, match="unknown recovery rule"):
        EvalConfig("learned", (2,), 1, 0, protocol="recovering", rules_off=("wizard",))
    with pytest.raises(InvalidInputError, match="no recovery rule"):
        EvalConfig("learned", (2,), 1, 0, protocol="paper", rules_off=("push_give_up",))
    with pytest.raises(InvalidInputError, match="protocol 'x'"):
        EvalConfig("learned", (2,), 1, 0, protocol="x")


def test_a_run_folder_names_its_protocol_unless_it_is_the_first_one():
    # runs were claimed under the recovering protocol before protocols were named
    first = run_config(EvalConfig("oracle", (2,), 1, 0, protocol="recovering"))
    assert "protocol" not in first and "rules_off" not in first
    paper = run_config(EvalConfig("oracle", (2,), 1, 0))
    assert paper["protocol"] == "paper" and paper["rules_off"] == []


def test_a_run_folder_records_f_ps_rules_where_they_differ_from_the_shipped():
    plain = run_config(EvalConfig("oracle", (2,), 1, 0))
    assert "perception_rules" not in plain  # as runs were claimed before
    set_ = run_config(EvalConfig("oracle", (2,), 1, 0, perception_rules=["pixel_vote=off"]))
    assert set_["perception_rules"] == ["pixel_vote=off"]
    assert set_["fingerprint"] == plain["fingerprint"]  # the same checkpoints
    with pytest.raises(InvalidInputError, match="perception rule"):
        EvalConfig("oracle", (2,), 1, 0, perception_rules=("pixel_vote=maybe",))


def test_an_ablation_switches_each_rule_off_in_turn_and_tables_them():
    from hsgplan.evaluation.ablation import ablation_table, variants
    from hsgplan.evaluation.summary import summarize
    from tests.evaluation.test_table1 import _record

    config = EvalConfig("learned", (2,), 1, 0, protocol="recovering")
    found = variants(config)
    assert list(found)[0] == "all-rules" and found["all-rules"].rules_off == ()
    acting = [r for r in RecoveryRules.names() if r not in PERCEPTION_RULES + CHECKING_RULES]
    assert [v.rules_off for v in list(found.values())[1:]] == [(r,) for r in acting]
    seeing = variants(config, seeing=True)  # relook acts only through the cameras
    assert [v.rules_off for v in list(seeing.values())[1:]] == [
        (r,) for r in RecoveryRules.names() if r not in CHECKING_RULES
    ]
    checking = variants(config, checking=True)  # refuse_repeats acts only in a checking agent
    assert {v.rules_off for v in checking.values()} >= {(r,) for r in CHECKING_RULES}
    with pytest.raises(InvalidInputError, match="ablate-rules"):
        variants(EvalConfig("learned", (2,), 1, 0, protocol="paper"))
    run = {"goals": 1, "goals_file": None, "repeats": 1, "seed": 0}
    ok, failed = summarize([_record(True)]), summarize([_record(False, "overstep", ("no_ik",))])
    report = {
        "variants": {
            "all-rules": run | {"methods": {"gnn": ok}},
            "no-push_give_up": run | {"methods": {"gnn": failed}},
        }
    }
    table = ablation_table(report)
    assert table.header == ("recovery rules", "GNN 2", "GNN failed primitives / episode")
    assert table.rows == (("all on", "1.00", "0.00"), ("push_give_up off", "0.00", "1.00"))


@pytest.mark.parametrize("protocol", ["paper", "recovering"])
def test_a_table_folder_claimed_under_a_protocol_is_its_own_again(tmp_path, protocol):
    from hsgplan.evaluation.ablation import ABLATION_KIND, _claimed_with
    from hsgplan.evaluation.table1 import TABLE_KIND, Method, check_table
    from hsgplan.runner.run_folder import check_claim, claim

    methods = [Method("gnn", "regression+gnn")]
    config = EvalConfig("", (2,), 1, 0, protocol=protocol)
    table, refusal = check_table(methods, config, tmp_path / "table")
    claim(tmp_path / "table", TABLE_KIND, table, refusal)
    again = check_table(methods, config, tmp_path / "table")  # refuses if it differs
    assert check_claim(tmp_path / "table", TABLE_KIND, *again)
    if protocol == "recovering":  # read back from JSON, a resumed ablation is the same one
        claim(tmp_path / "ablation", ABLATION_KIND, *_claimed_with(methods, config))
        assert check_claim(tmp_path / "ablation", ABLATION_KIND, *_claimed_with(methods, config))


def test_the_checking_agents_rules_are_ablated_only_where_some_method_checks_its_actions():
    from hsgplan.evaluation.ablation import _checking
    from hsgplan.evaluation.table1 import Method

    assert not _checking([Method("GNN", "learned"), Method("search", "search")])
    assert _checking([Method("GNN", "learned"), Method("c", "regression-ahead-clearing+gnn")])
