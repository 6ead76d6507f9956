"""The symbolic loop under both protocols: an inapplicable action costs its step, or, under the
paper's, ends the episode; the run folder keeps the protocol apart."""

import pytest

from hsgplan.domain.actions import Place
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.evaluation import task_eval
from hsgplan.evaluation.failures import Failure
from hsgplan.evaluation.task_eval import evaluate_task, run_task_episode
from hsgplan.paths import TASK_CHECKPOINT
from hsgplan.planning.base import TaskDecision

GOAL = parse_goal("On(cherries, shelf_a)", world=KITCHEN)


class Stubborn:
    """Places cherries, never picking them first: inapplicable from every start."""

    def next_action(self, state, goal):
        return TaskDecision(Place("cherries", "shelf_b"), None, 0.0)


def test_an_inapplicable_action_costs_a_step_or_ends_the_episode():
    recovering = run_task_episode(Stubborn(), GOAL, 3, 2)
    assert recovering.failure == Failure.OVERSTEP and recovering.wasted == recovering.steps
    paper = run_task_episode(Stubborn(), GOAL, 3, 2, end_at_failure=True)
    assert paper.failure == Failure.FAILED_PRIMITIVE and paper.steps == paper.wasted == 1


def test_the_protocol_is_part_of_a_runs_configuration_and_of_every_job(monkeypatch):
    runs = []

    def record(fn, jobs, config, **kwargs):
        runs.append((config, jobs))
        return []

    monkeypatch.setattr(task_eval, "run_items", record)
    for protocol in ("paper", "recovering"):
        evaluate_task("regression", TASK_CHECKPOINT, (2,), 2, 0, protocol=protocol)
    (paper, paper_jobs), (recovering, recovering_jobs) = runs
    assert paper["protocol"] == "paper" and all(j.protocol == "paper" for j in paper_jobs)
    # a recovering run's configuration is what it was before protocols: old runs resume
    assert "protocol" not in recovering
    assert all(j.protocol == "recovering" for j in recovering_jobs)
    with pytest.raises(InvalidInputError, match="protocol 'kind'"):
        evaluate_task("regression", TASK_CHECKPOINT, (2,), 2, 0, protocol="kind")


def test_a_split_draws_its_goals_from_its_share_and_is_part_of_the_runs_configuration(
    monkeypatch,
):
    from hsgplan.evaluation.splits import TEST, bucket

    runs = []
    monkeypatch.setattr(
        task_eval, "run_items", lambda fn, jobs, config, **kw: runs.append((config, jobs)) or []
    )
    start = TEST.seeds.start
    evaluate_task("fd", TASK_CHECKPOINT, (3,), 20, start, split="test")
    evaluate_task("fd", TASK_CHECKPOINT, (3,), 20, start)
    (split_config, jobs), (bare_config, bare_jobs) = runs
    assert split_config["split"] == "test" and "split" not in bare_config
    goals = [parse_goal(j.goal, world=KITCHEN) for j in jobs]
    assert all(bucket(g) in TEST.goal_share for g in goals)
    bare = [parse_goal(j.goal, world=KITCHEN) for j in bare_jobs]
    assert not all(bucket(g) in TEST.goal_share for g in bare)  # the whole space
    with pytest.raises(InvalidInputError, match="not a test seed"):
        evaluate_task("fd", TASK_CHECKPOINT, (3,), 2, 0, split="test")


def test_a_reference_search_out_of_time_scores_no_length_and_ends_nothing(monkeypatch):
    from hsgplan.planning import fast_downward

    def out_of_time(self, state, goal, banned=()):
        raise fast_downward.NoPlanError("no plan found within 60 s")

    monkeypatch.setattr(fast_downward.FastDownwardPlanner, "plan", out_of_time)
    assert task_eval.fd_length(GOAL, 3) == 0
