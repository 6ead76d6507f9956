"""The motion networks on tiny hand-built graphs: shapes, and invariance to object order."""

import pytest
import torch
from torch_geometric.data import Batch

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.predicates import inside, on
from hsgplan.motion.models import FlatMotionNet, MotionNetConfig, build
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.geometry import Pose
from hsgplan.scene_graph.grounding import ground


def _scene(order: list[str]) -> GeometricSceneGraph:
    poses = {
        "cherries": Pose.from_xyz_yaw(0.45, 0.36, 0.169),
        "butter": Pose.from_xyz_yaw(0.52, 0.30, 0.152, 0.2),
        "popcorn": Pose.from_xyz_yaw(0.40, 0.0, 0.35),
        "alphabet_soup": Pose.from_xyz_yaw(0.50, -0.1, 0.042),
    }
    sg = GeometricSceneGraph.from_poses(poses, held="popcorn", world=KITCHEN)
    # the same scene with its nodes in another order
    return GeometricSceneGraph(tuple(sg.node(n) for n in order), held="popcorn", world=KITCHEN)


def _permuted_pair():
    a = ground(_scene(["cherries", "butter", "popcorn", "alphabet_soup"]), on("popcorn", "shelf_a"))
    b = ground(_scene(["alphabet_soup", "popcorn", "cherries", "butter"]), on("popcorn", "shelf_a"))
    return a, b


MODELS = [(m, h) for m in ("gnn", "mlp") for h in ("mlp", "per-dim", "bins")]


@pytest.mark.parametrize("model,head", MODELS)
def test_shapes(model, head):
    config = MotionNetConfig(model, "place", (10, 10), hidden=16, embed=8, head=head)
    a, b = _permuted_pair()
    out = build(config)(Batch.from_data_list([a, b, a]))
    assert out.shape == (3, 100)
    push = MotionNetConfig(model, "push", (21, 21), hidden=16, embed=8, head=head)
    sg = GeometricSceneGraph.from_poses(
        {"cherries": Pose.from_xyz_yaw(0.3, 0.38, 0.029)}, world=KITCHEN
    )
    g = ground(sg, inside("cherries", "shelf_a"))  # a graph of one node and no edges
    assert build(push)(Batch.from_data_list([g])).shape == (1, 441)


@pytest.mark.parametrize("model", ["gnn", "mlp"])
def test_a_head_per_dimension_is_two_softmaxes_and_its_cross_entropy_their_sum(model):
    torch.manual_seed(0)
    net = build(MotionNetConfig(model, "push", (21, 21), hidden=16, embed=8, head="per-dim"))
    a, b = _permuted_pair()
    scores = net.eval()(Batch.from_data_list([a, b])).view(2, 21, 21)
    x, y = scores.logsumexp(dim=2), scores.logsumexp(dim=1)  # each dimension's log-probs
    assert torch.allclose(x.exp().sum(1), torch.ones(2), atol=1e-5)
    assert torch.allclose(scores, x.unsqueeze(2) + y.unsqueeze(1), atol=1e-5)  # independent
    pair = torch.tensor([3 * 21 + 17, 20 * 21 + 0])
    joint = torch.nn.functional.cross_entropy(scores.flatten(1), pair)
    each = torch.nn.functional.cross_entropy(x, pair // 21)
    each = each + torch.nn.functional.cross_entropy(y, pair % 21)
    assert torch.allclose(joint, each, atol=1e-5)


def test_a_head_per_dimension_learns_from_successes_only():
    from hsgplan.motion.train import MotionTrainConfig

    MotionTrainConfig(model="gnn", primitive="place", head="per-dim", loss="ce")
    with pytest.raises(InvalidInputError, match="per-dim"):
        MotionTrainConfig(model="gnn", primitive="place", head="per-dim", loss="bce")


def test_a_count_of_trials_is_refused_to_a_loss_of_successes():
    from hsgplan.motion.train import MotionTrainConfig

    MotionTrainConfig(loss="bce", trials=100)
    with pytest.raises(InvalidInputError, match="trials counts what loss 'bce' learns"):
        MotionTrainConfig(loss="ce", trials=100)


@pytest.mark.parametrize("model,head", MODELS)
def test_scoring_only_some_bins_gives_their_logits(model, head):
    """`only` (one bin per graph, what the bce loss trains) gives the logits that scoring
    every bin gives for those bins."""
    torch.manual_seed(0)
    net = build(MotionNetConfig(model, "place", (10, 10), hidden=16, embed=8, head=head)).eval()
    a, b = _permuted_pair()
    batch = Batch.from_data_list([a, b, a])
    only = torch.tensor([3, 57, 99])
    picked = net(batch, only=only)
    assert picked.shape == (3, 1)
    assert torch.allclose(picked[:, 0], net(batch)[torch.arange(3), only], atol=1e-5)


@pytest.mark.parametrize("model,head", MODELS)
def test_object_order_does_not_matter(model, head):
    torch.manual_seed(0)
    net = build(MotionNetConfig(model, "place", (10, 10), hidden=32, embed=8, head=head)).eval()
    a, b = _permuted_pair()
    assert not torch.equal(a.x, b.x)  # really another order
    out_a = net(Batch.from_data_list([a]))
    out_b = net(Batch.from_data_list([b]))
    assert torch.allclose(out_a, out_b, atol=1e-5)


@pytest.mark.parametrize("model,head", MODELS)
def test_every_model_reads_the_other_objects(model, head):
    torch.manual_seed(0)
    net = build(MotionNetConfig(model, "place", (10, 10), hidden=32, embed=8, head=head)).eval()
    a, _ = _permuted_pair()
    moved = a.clone()
    moved.x = a.x.clone()
    moved.x[0, -3:] += 0.5  # the first object elsewhere on the shelf top
    # an untrained network reads it faintly: a change far above float rounding is enough
    before, after = net(Batch.from_data_list([a])), net(Batch.from_data_list([moved]))
    assert not torch.allclose(before, after, rtol=0, atol=1e-6)


def test_the_mlp_flattens_by_type_slot():
    net = FlatMotionNet(MotionNetConfig("mlp", "place", (10, 10), hidden=16, embed=8))
    a, b = _permuted_pair()
    assert torch.equal(
        net.flatten(Batch.from_data_list([a])), net.flatten(Batch.from_data_list([b]))
    )


def test_the_mlp_bin_head_reads_each_type_slot_and_knows_the_absent_ones():
    net = FlatMotionNet(MotionNetConfig("mlp", "place", (10, 10), hidden=16, embed=8, head="bins"))
    a, b = _permuted_pair()
    positions, present = net._slot_positions(Batch.from_data_list([a, b]))
    assert torch.equal(positions[0], positions[1])  # by type, whatever the node order
    assert present.sum(dim=1).tolist() == [4, 4]  # four of the six types in the scene
    assert positions[~present].abs().sum() == 0


def test_bad_configurations_are_refused():
    with pytest.raises(InvalidInputError, match="model 'cnn'"):
        MotionNetConfig("cnn", "place", (10, 10))
    with pytest.raises(InvalidInputError, match="head 'query'"):
        MotionNetConfig("mlp", "place", (10, 10), head="query")
    with pytest.raises(InvalidInputError, match="hidden"):
        MotionNetConfig("gnn", "place", (10, 10), hidden=0)


def test_without_dropout_a_network_keeps_the_layers_networks_were_saved_with():
    from hsgplan.motion.layers import mlp

    assert [type(m).__name__ for m in mlp([4, 8, 8, 2])] == [
        "Linear", "ReLU", "Linear", "ReLU", "Linear",
    ]  # fmt: skip
    assert [type(m).__name__ for m in mlp([4, 8, 2], 0.5)] == [
        "Linear", "ReLU", "Dropout", "Linear",
    ]  # fmt: skip


@pytest.mark.parametrize("model,head", MODELS)
def test_dropout_draws_while_training_and_never_once_trained(model, head):
    config = MotionNetConfig(model, "place", (10, 10), hidden=16, embed=8, head=head, dropout=0.5)
    a, b = _permuted_pair()
    batch = Batch.from_data_list([a, b])
    net = build(config)
    torch.manual_seed(0)
    assert not torch.equal(net(batch), net(batch))
    net.eval()
    assert torch.equal(net(batch), net(batch))
    with pytest.raises(InvalidInputError, match="dropout"):
        MotionNetConfig(model, "place", (10, 10), dropout=1.0)
