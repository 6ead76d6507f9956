"""The search-based baseline: it solves goals in the simulated world, follows its refined plan,
and plans again when the world departs from it."""

import pytest

from hsgplan.agents.search import SearchAgent, _Search
from hsgplan.domain.actions import Pick, Place
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.parameters import PickParams
from hsgplan.evaluation.episode import run_episode
from hsgplan.sim.env import KitchenStorageEnv, ResetOptions
from hsgplan.sim.outcome import Outcome, Status


@pytest.mark.slow
def test_solves_a_three_object_goal():
    goal = parse_goal(
        "On(butter, shelf_b) & In(tomato_soup, shelf_a) & On(cherries, butter)", world=KITCHEN
    )
    record = run_episode(KitchenStorageEnv(world=KITCHEN), SearchAgent(), goal, seed=4)
    assert record.success, record.steps
    # one plan, refined once before the first step: later steps cost no planning time
    assert record.steps[0].task_seconds > 0 and record.steps[0].motion_seconds > 0
    assert all(s.task_seconds == 0 for s in record.steps[1:])


def test_follows_its_plan_and_plans_again_when_a_step_fails():
    goal = parse_goal("On(butter, shelf_b)", world=KITCHEN)
    env = KitchenStorageEnv(world=KITCHEN)
    _, info = env.reset(seed=5, options=ResetOptions(goal))
    obs = info["observation"]
    assert not goal.satisfied_by(obs.symbols.state)
    agent = SearchAgent()
    agent.reset(goal, 5)
    first = agent.decide(obs.scene_graph, obs.symbols.state, goal, env.lookahead)
    assert first.action == Pick("butter") and first.params == PickParams("butter")
    assert len(agent._queue) == 1  # the place, with its parameters already chosen
    agent.observe(first.params, Outcome(Status.NO_PATH, "", 0.0))
    assert agent._queue == []
    env.close()


def test_without_a_world_to_try_plans_in_it_offers_nothing():
    goal = parse_goal("On(butter, shelf_b)", world=KITCHEN)
    env = KitchenStorageEnv(world=KITCHEN)
    _, info = env.reset(seed=3, options=ResetOptions(goal))
    obs = info["observation"]
    d = SearchAgent().decide(obs.scene_graph, obs.symbols.state, goal, env.check)
    assert d.action is None and "world" in d.note
    env.close()


def test_bans_the_latest_step_not_banned_or_found_useless():
    search = _Search()
    search.blame = [Place("butter", "shelf_b"), Pick("butter"), Place("cherries", "prepush_a")]
    assert SearchAgent._ban_next(search) and search.bans == [Place("butter", "shelf_b")]
    search.useless.add(search.bans.pop())  # that ban left the goal unreachable
    assert SearchAgent._ban_next(search) and search.bans == [Pick("butter")]
    assert SearchAgent._ban_next(search) and len(search.bans) == 2
    assert not SearchAgent._ban_next(search)
