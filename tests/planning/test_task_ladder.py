"""The task ladder's rows (`configs/results/ladder-task`) change one thing each, from the paper's
recipe to the shipped configuration, and its controls are the size they claim."""

import json
from dataclasses import asdict
from itertools import pairwise

from hsgplan.data.demos import load_demos
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.paths import home
from hsgplan.planning.regression.examples import paper_reach_examples, world_reach_examples
from hsgplan.planning.regression.train import TaskTrainConfig

RESULTS = home() / "configs" / "results"
# each row's configuration and what it changes from the row above
STEPS = (
    ("paper-task.json", None),
    ("ladder-task/demos-v1.json", {"demos"}),
    ("ladder-task/hidden-32.json", {"hidden"}),
    # the copies at about as many updates: fewer epochs over 21 times the trajectories, and
    # f_reach, which learns from the demonstrations alone still, at the epochs it had
    ("ladder-task/copies.json", {"copies", "epochs", "save_every", "reach_epochs"}),
    ("ladder-task/vary.json", {"vary"}),
    ("ladder-task/world-reach-equal.json", {"reach", "reach_limit"}),
    ("ladder-task/world-reach.json", {"reach_limit", "reach_epochs"}),
    ("ladder-task/visited-equal.json", {"loop_trials", "reach_limit"}),
    ("task.json", {"reach_limit"}),
)


def _rows() -> dict[str, dict]:
    return {
        path: asdict(TaskTrainConfig.from_json(json.loads((RESULTS / path).read_text())))
        for path, _ in STEPS
    }


def test_each_row_changes_one_thing_from_the_row_above():
    rows = _rows()
    for (above, _), (path, changes) in pairwise(STEPS):
        row = rows[path]
        assert {k for k in row if row[k] != rows[above][k]} == changes, path


def test_the_copies_row_keeps_about_as_many_updates():
    rows = _rows()
    above, copies = rows["ladder-task/hidden-32.json"], rows["ladder-task/copies.json"]
    assert 1 <= (1 + copies["copies"]) * copies["epochs"] / above["epochs"] < 1.2
    assert copies["reach_epochs"] == above["epochs"]


def test_the_controls_learn_from_as_many_examples_as_the_rows_above():
    rows = _rows()
    # f_reach from the world, as large as the paper's f_reach on the same demonstrations
    paper = rows["ladder-task/vary.json"]
    demos = load_demos(home() / "data" / "demos" / "v1", KITCHEN)
    predicates = paper["reach"] == "predicates"
    size = len(paper_reach_examples(demos, 0, paper["reach_singles"], predicates))
    equal = rows["ladder-task/world-reach-equal.json"]
    assert equal["reach_limit"] + len(world_reach_examples([], demos)) == size
    # staged and visited states, as many as the staged alone (the shipped f_reach's count)
    labels = json.loads((home() / "checkpoints" / "task" / "reach" / "labels.json").read_text())
    staged = labels["primitives executed in the simulated world"]["examples"]
    assert rows["ladder-task/visited-equal.json"]["reach_limit"] == staged
