"""Training the keypoint network end to end on a tiny collection: it finishes into a
checkpoint folder that loads, and a second run with the same configuration does nothing.
How well it learns is measured by `hsgplan eval-perception`, not here."""

import pytest
import torch

from hsgplan.domain.errors import InvalidInputError
from hsgplan.perception.images import ImagesConfig, collect_images
from hsgplan.perception.model import STRIDE, load_perception_net
from hsgplan.perception.synthetic import VIEWS
from hsgplan.perception.train import PerceptionTrainConfig, train_perception


def test_a_tiny_training_makes_a_checkpoint_that_loads_and_is_not_redone(tmp_path):
    images = tmp_path / "images"
    collect_images(ImagesConfig(count=2, chunk=2), images, workers=1)
    config = PerceptionTrainConfig(
        images=str(images), epochs=1, batch_size=3, width=4, stages=1, threads=1
    )
    losses = []
    train_perception(config, tmp_path / "net", lambda e, loss: losses.append(loss))
    assert len(losses) == 1 and losses[0] > 0
    net, net_config = load_perception_net(tmp_path / "net")
    ((beliefs, fields),) = net(torch.zeros(1, 3, VIEWS[0].height, VIEWS[0].width))
    assert beliefs.shape == (
        1,
        net_config.beliefs,
        VIEWS[0].height // STRIDE,
        VIEWS[0].width // STRIDE,
    )
    assert fields.shape[1] == net_config.fields
    again = []
    train_perception(config, tmp_path / "net", lambda e, loss: again.append(loss))
    assert again == []
    with pytest.raises(InvalidInputError, match="another configuration"):
        train_perception(
            PerceptionTrainConfig(images=str(images), epochs=2, width=4, stages=1),
            tmp_path / "net",
        )


def test_positive_weight_makes_a_missed_keypoint_cost_more_than_a_false_one():
    from hsgplan.perception.train import loss_of

    target = torch.zeros(1, 1, 4, 4)
    target[0, 0, 1, 1] = 1.0
    fields = torch.zeros(1, 2, 4, 4)
    missed = [(torch.zeros_like(target), fields)]
    false = torch.zeros_like(target)
    false[0, 0, 2, 2] = 1.0
    spurious = [(false + target, fields)]  # the keypoint found, and one more where none is
    assert loss_of(missed, target, fields) == loss_of(spurious, target, fields)
    assert loss_of(missed, target, fields, 10.0) > loss_of(spurious, target, fields, 10.0)
