"""The learned regression planner, trained here on the shipped demonstrations (small and short,
so that it runs in the suite), closing the symbolic loop on goals no demonstration shows."""

import random
from pathlib import Path

import pytest
import torch

from hsgplan.domain.generator import random_state
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.predicates import on
from hsgplan.domain.transition import Pick, Place, apply
from hsgplan.evaluation.task_eval import run_task_episode
from hsgplan.planning.regression.planner import RegressionPlanner
from hsgplan.planning.regression.train import TaskTrainConfig, train_task
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph

DEMOS = Path(__file__).resolve().parents[2] / "data" / "demos" / "v1"
SMALL = {
    "demos": str(DEMOS),
    "epochs": 10,
    "hidden": 32,
    "rounds": 3,
    "copies": 3,
    "reach_singles": 4,
    "batch_size": 32,
}


@pytest.fixture(scope="module")
def checkpoint(tmp_path_factory) -> Path:
    torch.set_num_threads(1)
    out = tmp_path_factory.mktemp("task")
    train_task(TaskTrainConfig.from_json(SMALL), out)
    return out


@pytest.mark.parametrize(
    "goal",
    [
        "On(cherries, shelf_a) & On(butter, cherries) & In(tomato_soup, shelf_a)",
        "On(popcorn, shelf_b) & In(alphabet_soup, shelf_a) & On(cream_cheese, shelf_a)",
    ],
)
def test_a_checkpoint_trained_on_the_demos_solves_three_object_goals(checkpoint, goal):
    g = parse_goal(goal)
    for seed in range(3):  # start states with stacks and objects on shelf tops among them
        episode = run_task_episode(RegressionPlanner(checkpoint, seed=seed), g, seed, 0)
        assert episode.success, (seed, episode.failure, episode.steps)
        assert episode.steps <= 12  # no wandering: at most a few steps more than needed


def test_the_same_seed_gives_the_same_decisions(checkpoint):
    g = parse_goal("On(cherries, shelf_a) & On(butter, cherries) & In(tomato_soup, shelf_a)")
    state = random_state(g.objects, random.Random(0))
    runs = []
    for _ in range(2):
        planner, s, actions = RegressionPlanner(checkpoint, seed=7), state, []
        while not g.satisfied_by(s) and len(actions) < 20:
            a = planner.next_action(s, g).action
            actions.append(str(a))
            s = apply(s, a)
        runs.append(actions)
    assert runs[0] == runs[1]


def test_a_stack_waits_for_its_base_and_an_object_in_the_way_is_moved(checkpoint):
    # butter sits on cherries, and the goal wants cherries on shelf A with butter on top
    start = SymbolicSceneGraph.from_literals(
        ["cherries", "butter"], [on("cherries", "open_space"), on("butter", "cherries")]
    )
    goal = parse_goal("On(cherries, shelf_a) & On(butter, cherries)")
    planner, s, actions = RegressionPlanner(checkpoint, seed=0), start, []
    while not goal.satisfied_by(s) and len(actions) < 12:
        a = planner.next_action(s, goal).action
        actions.append(a)
        s = apply(s, a)
    assert goal.satisfied_by(s)
    assert actions[0] == Pick("butter") and actions[1] != Place("butter", "cherries")
    assert len(actions) == 6  # the shortest plan: butter off, cherries up, butter back on
