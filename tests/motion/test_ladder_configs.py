"""The motion ladder's rows change only what they name: the head and the loss."""

import json

import pytest

from hsgplan.motion.train import MotionTrainConfig
from hsgplan.paths import MOTION_CHECKPOINTS, home

LADDER = home() / "configs" / "ladder"
ROWS = {
    "paper-head-ce": {"head": "mlp", "loss": "ce"},
    "paper-per-dim-ce": {"head": "per-dim", "loss": "ce"},
    "bin-inputs-ce": {"head": "bins", "loss": "ce"},
}


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
def test_networks_trained_round_layouts_differ_from_the_kitchens_in_their_data_only(kind):
    config = json.loads((home() / "configs" / "layouts-motion" / f"{kind}-gnn.json").read_text())
    baseline = home() / "checkpoints" / "motion-geometry" / f"{kind}-gnn" / "train_config.json"
    kitchen = json.loads(baseline.read_text())
    MotionTrainConfig.from_json(config)
    assert {k for k in kitchen if config[k] != kitchen[k]} == {"data"}
    assert set(config) == set(kitchen)
    shipped = home() / "checkpoints" / "motion-geometry-layouts" / f"{kind}-gnn"
    assert json.loads((shipped / "train_config.json").read_text()) == config
