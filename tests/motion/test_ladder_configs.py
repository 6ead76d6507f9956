"""The motion ladder's rows change only what they name: the head, the loss, the trials."""

import json
from dataclasses import asdict
from itertools import pairwise

import pytest

from hsgplan.motion.train import MotionTrainConfig
from hsgplan.paths import MOTION_CHECKPOINTS, home

LADDER = home() / "configs" / "ladder"
ROWS = {
    "paper-head-ce": {"head": "mlp", "loss": "ce"},
    "paper-per-dim-ce": {"head": "per-dim", "loss": "ce"},
}
RESULTS = home() / "configs" / "results"
# the results plan's motion ladder, from the paper's recipe to the shipped networks: each row's
# configuration and what it changes from the row above
STEPS = (
    ("paper-{kind}-gnn.json", None),
    ("ladder-motion/bins-ce/{kind}-gnn.json", {"head"}),
    ("ladder-motion/bce-equal/{kind}-gnn.json", {"loss", "trials"}),
    ("ladder-motion/every/{kind}-gnn.json", {"trials"}),
    # the settings searched on held-out loss (`motion settings` in the record of choices)
    ("{kind}-gnn.json", {"place": set(), "push": {"weight_decay"}}),
)


@pytest.mark.parametrize("row", sorted(ROWS))
@pytest.mark.parametrize("kind", ["place", "push"])
def test_a_row_differs_from_the_shipped_gnn_in_its_head_and_loss_only(row, kind):
    config = json.loads((LADDER / row / f"{kind}-gnn.json").read_text())
    shipped = json.loads((MOTION_CHECKPOINTS / f"{kind}-gnn" / "train_config.json").read_text())
    MotionTrainConfig.from_json(config)  # a configuration training takes
    assert {k for k in shipped if config[k] != shipped[k]} <= {"head", "loss"}
    assert {k: config[k] for k in ROWS[row]} == ROWS[row]
    assert set(config) == set(shipped)


@pytest.mark.parametrize("kind", ["place", "push"])
def test_each_row_of_the_ladder_changes_one_thing_from_the_row_above(kind):
    rows = []
    for path, changes in STEPS:
        config = json.loads((RESULTS / path.format(kind=kind)).read_text())
        changes = changes[kind] if isinstance(changes, dict) else changes
        rows.append((asdict(MotionTrainConfig.from_json(config)), changes))
    for (above, _), (row, changes) in pairwise(rows):
        assert {k for k in row if row[k] != above[k]} == changes
    # the control learns from as many examples as the successes of the row above
    (bins, _), (control, _) = rows[1], rows[2]
    assert control["trials"] == bins["samples"]


@pytest.mark.parametrize("kind", ["place", "push"])
def test_networks_trained_round_layouts_differ_from_the_kitchens_in_their_data_only(kind):
    config = json.loads((home() / "configs" / "layouts-motion" / f"{kind}-gnn.json").read_text())
    baseline = home() / "checkpoints" / "motion-geometry" / f"{kind}-gnn" / "train_config.json"
    kitchen = json.loads(baseline.read_text())
    MotionTrainConfig.from_json(config)
    assert {k for k in kitchen if config[k] != kitchen[k]} == {"data"}
    assert set(config) == set(kitchen)
    shipped = home() / "checkpoints" / "motion-geometry-layouts" / f"{kind}-gnn"
    assert json.loads((shipped / "train_config.json").read_text()) == config
