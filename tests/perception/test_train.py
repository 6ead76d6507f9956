"""Training the keypoint network end to end on a tiny collection: it finishes into a
checkpoint folder that loads, and a second run with the same configuration does nothing.
How well it learns is measured by `hsgplan eval perception`, not here."""

import pytest
import torch

from hsgplan.collect.images import ImagesConfig, collect_images
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.perception.estimator import PoseEstimator
from hsgplan.perception.model import PerceptionNetConfig, build, load_perception_net
from hsgplan.perception.train import PerceptionTrainConfig, train_perception
from hsgplan.perception.vocabulary import kitchen_vocabulary

VIEWS = kitchen_vocabulary().views  # the shipped f_p's fixed cameras


def test_a_tiny_training_makes_a_checkpoint_that_loads_and_is_not_redone(tmp_path):
    images = tmp_path / "images"
    collect_images(ImagesConfig(samples=2, chunk=2), images, workers=1)
    config = PerceptionTrainConfig(
        images=str(images), epochs=1, batch_size=3, width=4, stages=1, threads=1, stride=2
    )
    losses = []
    train_perception(config, tmp_path / "net", lambda e, loss: losses.append(loss))
    assert len(losses) == 1 and losses[0] > 0
    net, net_config = load_perception_net(tmp_path / "net")
    outputs = net(torch.zeros(1, 3, VIEWS[0].height, VIEWS[0].width))
    assert net_config.stride == 2 and len(outputs) == 2  # the stage, and its refinement
    for beliefs, fields in outputs:
        assert beliefs.shape == (1, net_config.beliefs, VIEWS[0].height // 2, VIEWS[0].width // 2)
        assert fields.shape[1] == net_config.fields
    estimator = PoseEstimator.load(tmp_path / "net")  # the colour network beside it
    assert estimator.colour is not None
    again = []
    train_perception(config, tmp_path / "net", lambda e, loss: again.append(loss))
    assert again == []
    with pytest.raises(InvalidInputError, match="another configuration"):
        train_perception(
            PerceptionTrainConfig(images=str(images), epochs=2, width=4, stages=1, stride=2),
            tmp_path / "net",
        )


def test_a_stride_2_network_starts_from_a_stride_4_one_and_a_bad_stride_is_refused(tmp_path):
    images = tmp_path / "images"
    collect_images(ImagesConfig(samples=1, chunk=1), images, workers=1)
    base = PerceptionTrainConfig(
        images=str(images), epochs=1, batch_size=3, width=4, stages=1, threads=1, stride=4
    )
    train_perception(base, tmp_path / "s4")
    coarse = load_perception_net(tmp_path / "s4")[0]
    from hsgplan.perception.train import _start_from

    fine = build(PerceptionNetConfig(width=4, stages=1, stride=2))
    _start_from(fine, coarse)
    for name, value in coarse.state_dict().items():
        assert torch.equal(fine.state_dict()[name], value)
    assert fine.refine is not None
    wider = build(PerceptionNetConfig(width=8, stages=1, stride=2))
    with pytest.raises(InvalidInputError, match="more than its stride"):
        _start_from(wider, coarse)
    with pytest.raises(InvalidInputError, match="stride 3"):
        PerceptionNetConfig(stride=3)
    two = PerceptionTrainConfig(images=f"{images}, {images}", epochs=1, width=4, stages=1)
    assert two.folders == [images, images]


def _one_keypoint():
    target = torch.zeros(1, 1, 4, 4)
    target[0, 0, 1, 1] = 1.0
    target[0, 0, 1, 2] = 0.5
    return target, torch.zeros(1, 2, 4, 4)


def test_the_belief_loss_is_least_at_the_target_and_positive_weight_makes_a_miss_cost_more():
    from hsgplan.perception.train import loss_of

    target, fields = _one_keypoint()
    exact = loss_of([(target, fields)], target, fields, 20.0)
    for wrong in (torch.zeros_like(target), target.roll(1, dims=3), target * 0.8):
        assert loss_of([(wrong, fields)], target, fields, 20.0) > exact
    missed = [(torch.zeros_like(target), fields)]
    false = target.clone()
    false[0, 0, 3, 3] = 1.0  # the keypoint found, and one more where none is
    spurious = [(false, fields)]
    assert loss_of(missed, target, fields, 20.0) > loss_of(spurious, target, fields, 20.0)


def test_fields_are_trained_only_near_a_corner():
    from hsgplan.perception.train import loss_of

    target, fields = _one_keypoint()
    fields[0, :, 1, 1] = torch.tensor([2.0, -1.0])
    right = fields.clone()
    right[0, :, 3, 3] = 5.0  # anything, far from every corner
    wrong = fields.clone()
    wrong[0, 0, 1, 1] = 0.0
    base = loss_of([(target, fields)], target, fields)
    assert loss_of([(target, right)], target, fields) == base
    assert loss_of([(target, wrong)], target, fields) > base


def test_colour_features_read_the_patch_around_a_pixel_and_nothing_outside_the_image():
    import numpy as np

    from hsgplan.perception.colour import features

    image = np.zeros((20, 30, 3), dtype=np.uint8)
    image[5:15, 10:20] = (200, 40, 40)
    row = features(image, np.array([14.6, 9.8]))
    assert row is not None and row[0] > 0.7 and abs(row[3] - 280 / 3 / 255) < 1e-6
    assert features(image, np.array([35.0, 5.0])) is None
    assert features(image, np.array([np.nan, 5.0])) is None


def test_background_patches_lie_outside_every_objects_cuboid():
    import numpy as np

    from hsgplan.perception.colour import BACKGROUND
    from hsgplan.perception.train import BACKGROUND_PATCHES, Examples, colour_samples

    image = np.zeros((40, 60, 3), dtype=np.uint8)
    image[:, :30] = (200, 40, 40)  # the object's side of the image; the rest is black
    corners = np.array([[u, v] for u in (0, 29) for v in (0, 39)] * 2 + [[15, 20]], float)
    found = Examples(
        torch.from_numpy(image).permute(2, 0, 1)[None],
        [corners[None]],
        [np.array([3])],
        [corners[None]],
    )
    rows = colour_samples(found)
    assert [t for _, t in rows] == [3] + [BACKGROUND] * BACKGROUND_PATCHES
    assert all(r[3] < 1e-3 for r, _ in rows[1:])  # black: no pixel of their patches is red


def test_examples_keep_the_keypoints_of_objects_in_sight_and_the_cuboids_of_all():
    import numpy as np

    from hsgplan.perception.keypoints import PinholeCamera, view_keypoints
    from hsgplan.perception.train import MIN_VISIBLE, examples
    from hsgplan.scene_graph.geometry import Pose

    c = VIEWS[0]
    poses = [Pose.from_xyz_yaw(0.45, y, 0.05, 0.0) for y in (-0.1, 0.0, 0.1)]
    data = {
        "images": np.zeros((1, 1, c.height, c.width, 3), np.uint8),
        "types": np.array([[3, -1, 5]], np.int8),  # a gap in the slots
        "poses": np.array([[[*p.position, *p.orientation] for p in poses]], np.float32),
        "visible": np.array([[[MIN_VISIBLE - 1, 0, MIN_VISIBLE]]], np.int32),
        "cameras": np.array([[[*c.eye, *c.target, c.fov]]], np.float32),
    }
    found = examples(data, kitchen_vocabulary())
    names = list(KITCHEN.object_types)
    camera = PinholeCamera.of(c)
    assert [list(t) for t in found.types] == [[5]]  # the popcorn is barely in sight
    expected = view_keypoints(KITCHEN.object_type(names[5]), poses[2], camera)
    assert np.allclose(found.keypoints[0][0], expected, atol=1e-3)
    assert found.cuboids[0].shape == (2, 9, 2)
    assert np.allclose(found.cuboids[0][1], expected, atol=1e-3)
    assert np.allclose(
        found.cuboids[0][0],
        view_keypoints(KITCHEN.object_type(names[3]), poses[0], camera),
        atol=1e-3,
    )


def test_collections_of_different_view_counts_train_together(tmp_path):
    three, every = tmp_path / "three", tmp_path / "every"
    collect_images(ImagesConfig(samples=1, chunk=1, views=3), three, workers=1)
    collect_images(ImagesConfig(samples=1, chunk=1), every, workers=1)
    from hsgplan.perception.images import load_chunks
    from hsgplan.perception.train import examples, joined

    parts = [examples(load_chunks(f), kitchen_vocabulary()) for f in (three, every)]
    both = joined(parts)
    assert len(both.images) == 3 + len(VIEWS) == len(both.keypoints) == len(both.cuboids)
    assert torch.equal(both.images[3:], parts[1].images)
    config = PerceptionTrainConfig(
        images=f"{three},{every}", epochs=1, batch_size=4, width=4, stages=1, threads=1
    )
    losses = []
    train_perception(config, tmp_path / "net", lambda e, loss: losses.append(loss))
    assert len(losses) == 1 and losses[0] > 0


@pytest.mark.parametrize("stride", [2, 4])
def test_a_look_reads_the_last_output_alone_as_training_sees_it(stride):
    torch.manual_seed(0)
    net = build(PerceptionNetConfig(width=4, stages=2, stride=stride)).eval()
    image = torch.rand(2, 3, 32, 48)
    with torch.inference_mode():
        beliefs, fields = net(image)[-1]
        last = net.last(image)
    assert torch.equal(last[0], beliefs) and torch.equal(last[1], fields)
