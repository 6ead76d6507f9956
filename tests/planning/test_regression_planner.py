"""The learned regression planner, trained here on the shipped demonstrations (small and short,
so that it runs in the suite), closing the symbolic loop on goals no demonstration shows."""

import random
from pathlib import Path

import torch

from hsgplan.domain.actions import Pick, Place
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.predicates import on
from hsgplan.evaluation.task_eval import run_task_episode
from hsgplan.planning.regression.planner import RegressionPlanner
from hsgplan.planning.regression.train import TaskTrainConfig, train_task
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.symbolic.generator import random_state
from hsgplan.symbolic.transition import apply

DEMOS = Path(__file__).resolve().parents[2] / "data" / "demos" / "v1"
SMALL = {
    "demos": str(DEMOS),
    "epochs": 8,
    "hidden": 32,
    "rounds": 3,
    "copies": 12,
    "reach_copies": 3,
    "reach_singles": 4,
    "batch_size": 32,
}
GOALS = [
    "On(cherries, shelf_a) & On(butter, cherries) & In(tomato_soup, shelf_a)",
    "On(popcorn, shelf_b) & In(alphabet_soup, shelf_a) & On(cream_cheese, shelf_a)",
]


def test_a_checkpoint_trained_here_on_the_demos_solves_three_object_goals(tmp_path):
    # one test, so that parallel workers do not each train the checkpoint
    torch.set_num_threads(1)
    train_task(TaskTrainConfig.from_json(SMALL), tmp_path)
    for goal in map(parse_goal, GOALS):
        for seed in range(3):  # start states with stacks and objects on shelf tops among them
            episode = run_task_episode(RegressionPlanner(tmp_path, seed=seed), goal, seed, 0)
            assert episode.success, (str(goal), seed, episode.failure, episode.steps)
            assert episode.steps <= 12  # no wandering: at most a few steps more than needed

    # the same seed, the same decisions
    goal = parse_goal(GOALS[0])
    start = random_state(goal.objects, random.Random(0))
    assert _rollout(tmp_path, 7, start, goal) == _rollout(tmp_path, 7, start, goal)

    # butter sits on cherries, and the goal wants cherries on shelf A with butter on top
    start = SymbolicSceneGraph.from_literals(
        ["cherries", "butter"], [on("cherries", "open_space"), on("butter", "cherries")]
    )
    actions = _rollout(
        tmp_path, 0, start, parse_goal("On(cherries, shelf_a) & On(butter, cherries)")
    )
    assert actions[0] == str(Pick("butter")) and actions[1] != str(Place("butter", "cherries"))
    assert len(actions) == 6  # the shortest plan: butter off, cherries up, butter back on


def _rollout(checkpoint: Path, seed: int, state, goal) -> list[str]:
    planner, actions = RegressionPlanner(checkpoint, seed=seed), []
    while not goal.satisfied_by(state) and len(actions) < 20:
        action = planner.next_action(state, goal).action
        assert action is not None, actions
        actions.append(str(action))
        state = apply(state, action)
    assert goal.satisfied_by(state), actions
    return actions
