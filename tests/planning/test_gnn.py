"""The per-edge graph classifier: shapes, symmetry, batching, the loss, learning mechanics."""

import pytest
import torch
from torch_geometric.data import Batch, Data

from hsgplan.planning.regression.gnn import (
    EdgeClassifier,
    EdgeClassifierConfig,
    RelationalLayer,
    masked_cross_entropy,
)


def complete_graph(n: int, node_dim: int, edge_dim: int, gen: torch.Generator) -> Data:
    """Every ordered pair including self loops, as the symbolic scene graphs are laid out."""
    pairs = [(i, j) for i in range(n) for j in range(n)]
    edge_index = torch.tensor(pairs, dtype=torch.long).t().contiguous()
    return Data(
        x=torch.randn(n, node_dim, generator=gen),
        edge_index=edge_index,
        edge_attr=torch.randn(len(pairs), edge_dim, generator=gen),
    )


def model(**overrides) -> EdgeClassifier:
    torch.manual_seed(0)
    config = EdgeClassifierConfig(**{"node_dim": 5, "edge_dim": 4, "hidden": 16, **overrides})
    return EdgeClassifier(config).eval()


def test_output_shapes_on_a_three_node_complete_graph_with_self_loops():
    g = complete_graph(3, 5, 4, torch.Generator().manual_seed(1))
    assert model()(g).shape == (9, 4, 3)
    assert model(predicates=2, classes=2)(g).shape == (9, 2, 2)

    x, e = RelationalLayer(5, 4, 16)(g.x, g.edge_index, g.edge_attr)
    assert x.shape == (3, 16) and e.shape == (9, 16)  # no self loops added or removed


def test_relational_layer_sums_incoming_and_outgoing_edges():
    layer = RelationalLayer(2, 2, 2).eval()
    x = torch.zeros(3, 2)
    edge_attr = torch.ones(2, 2)
    # Node 0 receives two edges, node 1 one, node 2 none: sums must see the difference.
    two = layer(x, torch.tensor([[1, 2], [0, 0]]), edge_attr)[0]
    one = layer(x, torch.tensor([[1], [0]]), edge_attr[:1])[0]
    e = layer.edge_mlp(torch.cat([x[1], x[0], edge_attr[0]]))
    zero = torch.zeros_like(e)
    torch.testing.assert_close(two[0], layer.node_mlp(torch.cat([x[0], 2 * e, zero])) + x[0])
    # the senders see what they sent: an object learns what it rests on
    torch.testing.assert_close(two[1], layer.node_mlp(torch.cat([x[1], zero, e])) + x[1])
    assert not torch.allclose(two[0], one[0])


def test_a_silenced_edge_is_read_out_but_passes_nothing_on():
    layer = RelationalLayer(2, 2, 2).eval()
    x, edge_attr = torch.randn(3, 2), torch.randn(2, 2)
    edge_index = torch.tensor([[1, 2], [0, 0]])
    with torch.no_grad():
        x_all, e_all = layer(x, edge_index, edge_attr)
        x_one, e_one = layer(x, edge_index, edge_attr, torch.tensor([1.0, 0.0]))
        x_ref, _ = layer(x, edge_index[:, :1], edge_attr[:1])
    torch.testing.assert_close(e_one, e_all)  # still updated, so still classified
    torch.testing.assert_close(x_one, x_ref)  # as if the edge were not there
    assert not torch.allclose(x_one[0], x_all[0])


def test_outputs_are_equivariant_to_node_and_edge_order():
    gen = torch.Generator().manual_seed(2)
    g = complete_graph(4, 5, 4, gen)
    perm = torch.randperm(4, generator=gen)  # new node a is old node perm[a]
    new_of_old = torch.argsort(perm)
    edge_perm = torch.randperm(g.num_edges, generator=gen)
    h = Data(
        x=g.x[perm],
        edge_index=new_of_old[g.edge_index][:, edge_perm],
        edge_attr=g.edge_attr[edge_perm],
    )
    net = model()
    with torch.no_grad():
        torch.testing.assert_close(net(h), net(g)[edge_perm], rtol=1e-5, atol=1e-5)


def test_a_batch_gives_the_same_outputs_as_each_graph_alone():
    gen = torch.Generator().manual_seed(3)
    graphs = [complete_graph(3, 5, 4, gen), complete_graph(5, 5, 4, gen)]
    net = model()
    with torch.no_grad():
        batched = net(Batch.from_data_list(graphs))
        alone = torch.cat([net(g) for g in graphs])
    torch.testing.assert_close(batched, alone, rtol=1e-5, atol=1e-5)


def test_config_round_trips_through_json_and_refuses_unknown_keys():
    config = EdgeClassifierConfig(node_dim=7, edge_dim=3, predicates=2, classes=2, rounds=1)
    assert EdgeClassifierConfig.from_json(config.to_json()) == config
    assert EdgeClassifierConfig.from_json({"node_dim": 7, "edge_dim": 3}).hidden == 256
    with pytest.raises(ValueError, match="hiden"):
        EdgeClassifierConfig.from_json({**config.to_json(), "hiden": 8})
    with pytest.raises(ValueError):
        EdgeClassifierConfig.from_json({"node_dim": 7})
    with pytest.raises(ValueError):
        EdgeClassifierConfig(node_dim=7, edge_dim=3, classes=1)


def test_masked_cross_entropy_ignores_masked_out_entries():
    gen = torch.Generator().manual_seed(4)
    logits = torch.randn(6, 4, 3, generator=gen)
    target = torch.randint(0, 3, (6, 4), generator=gen)
    mask = torch.rand(6, 4, generator=gen) < 0.5
    loss = masked_cross_entropy(logits, target, mask)
    changed = logits.clone()
    changed[~mask] = 100 * torch.randn(int((~mask).sum()), 3, generator=gen)
    torch.testing.assert_close(masked_cross_entropy(changed, target, mask), loss)
    expected = torch.nn.functional.cross_entropy(logits[mask], target[mask])
    torch.testing.assert_close(loss, expected)


def test_masked_cross_entropy_of_an_empty_mask_is_zero_with_a_gradient():
    logits = torch.randn(5, 4, 3, requires_grad=True)
    loss = masked_cross_entropy(
        logits, torch.zeros(5, 4, dtype=torch.long), torch.zeros(5, 4).bool()
    )
    assert torch.isfinite(loss) and loss.item() == 0.0
    loss.backward()
    assert torch.equal(logits.grad, torch.zeros_like(logits))


def test_what_an_edge_is_told_reaches_it_only_through_message_passing():
    # The control that decides whether a rule such as "s -> t holds when a third node has a
    # property" is learnable at all: with no rounds an edge's output reads only its own
    # endpoints, with rounds it reads a node elsewhere in the graph.
    g = complete_graph(3, 5, 4, torch.Generator().manual_seed(5))
    third = g.clone()
    third.x = g.x.clone()
    third.x[2] += 1.0  # change node 2 only
    edge = 1  # the edge 0 -> 1
    for rounds, reads_node_2 in ((0, False), (1, True), (3, True)):
        net = model(rounds=rounds)
        changed = not torch.allclose(net(g)[edge], net(third)[edge], atol=1e-6)
        assert changed == reads_node_2, rounds


def test_one_optimiser_step_lowers_the_loss_on_a_fixed_batch():
    # Mechanics of learning (gradients reach every weight, the loss falls), not its quality.
    gen = torch.Generator().manual_seed(3)
    batch = Batch.from_data_list([complete_graph(3, 5, 4, gen) for _ in range(4)])
    target = torch.randint(0, 3, (batch.edge_index.shape[1], 4), generator=gen)
    mask = torch.ones_like(target, dtype=torch.bool)
    net = model().train()
    opt = torch.optim.SGD(net.parameters(), lr=1e-2)
    before = masked_cross_entropy(net(batch), target, mask)
    before.backward()
    assert all(p.grad is not None and p.grad.abs().sum() > 0 for p in net.parameters())
    opt.step()
    with torch.no_grad():
        assert masked_cross_entropy(net(batch), target, mask) < before


def test_reading_out_a_few_edges_gives_what_the_whole_graph_gives_there():
    gen = torch.Generator().manual_seed(7)
    g = complete_graph(5, 5, 4, gen)
    g.active = torch.rand(g.num_edges, generator=gen) < 0.4
    net = model()
    with torch.no_grad():
        whole = net(g)
        g.readout = torch.zeros(g.num_edges, dtype=torch.bool)
        g.readout[[3, 11, 17]] = True
        some = net(g)
    computed = g.active | g.readout
    torch.testing.assert_close(some[computed], whole[computed], rtol=1e-5, atol=1e-5)
    assert (some[~computed] == 0).all()


def test_masked_graphs_stay_equivariant_to_node_order():
    gen = torch.Generator().manual_seed(8)
    g = complete_graph(4, 5, 4, gen)
    g.active = torch.rand(g.num_edges, generator=gen) < 0.5
    perm = torch.randperm(4, generator=gen)
    new_of_old = torch.argsort(perm)
    h = Data(x=g.x[perm], edge_index=new_of_old[g.edge_index], edge_attr=g.edge_attr)
    h.active = g.active
    net = model()
    with torch.no_grad():
        torch.testing.assert_close(net(h), net(g), rtol=1e-5, atol=1e-5)


def test_the_scripted_network_gives_the_eager_outputs():
    gen = torch.Generator().manual_seed(9)
    g = complete_graph(4, 5, 4, gen)
    g.active = torch.rand(g.num_edges, generator=gen) < 0.5
    net = model()
    with torch.no_grad():
        eager = net(g)
        g.readout = torch.zeros(g.num_edges, dtype=torch.bool)
        g.readout[2] = True
        eager_some = net(g)
        net.script()
        torch.testing.assert_close(net(g), eager_some, rtol=1e-5, atol=1e-5)
        del g.readout
        torch.testing.assert_close(net(g), eager, rtol=1e-5, atol=1e-5)


@pytest.mark.filterwarnings("ignore:`torch.jit.freeze` is deprecated:DeprecationWarning")
@pytest.mark.parametrize("pool", [False, True])
def test_the_inference_core_is_the_pyg_core_bit_for_bit(pool):
    # the planner's decisions must not move: the same numbers, not merely close ones
    from hsgplan.planning.regression.gnn import _Core, _InferenceCore

    gen = torch.Generator().manual_seed(10)
    net = model(rounds=3, pool=pool)
    pyg = torch.jit.freeze(torch.jit.script(_Core(net).eval()))
    plain = torch.jit.freeze(torch.jit.script(_InferenceCore(net).eval()))
    scripted = model(rounds=3, pool=pool).script()  # the same weights (same seed)
    with torch.no_grad():
        # Six nodes at least, as every planner batch has (five fixtures and an object): below
        # five rows MKL multiplies another way and the last bits of `script` may differ.
        for n in (6, 7, 12):
            g = complete_graph(n, 5, 4, gen)
            keep = (torch.rand(g.num_edges, generator=gen) < 0.6).nonzero().squeeze(1)
            weight = (torch.rand(len(keep), generator=gen) < 0.7).float()
            batch = (torch.arange(n) >= n // 2).long()  # two graphs' worth of nodes
            args = (g.x, g.edge_index[:, keep], g.edge_attr[keep])
            expected = pyg(*args, weight, batch)
            assert torch.equal(plain(*args, weight, batch), expected)
            # optimize_for_inference may fuse in another order: the last bits can differ
            torch.testing.assert_close(
                scripted.computed(*args, weight, batch).flatten(1), expected, rtol=1e-6, atol=1e-6
            )
            assert torch.equal(plain(*args, None, None), pyg(*args, None, None))


def _silent_pair(x: torch.Tensor, gen: torch.Generator) -> Data:
    """Nodes 0 and 1 related by nothing: only self loops pass messages."""
    g = complete_graph(len(x), 5, 4, gen)
    g.x = x
    g.active = g.edge_index[0] == g.edge_index[1]
    return g


def test_without_pool_an_unrelated_node_changes_nothing_and_with_pool_it_does():
    gen = torch.Generator().manual_seed(11)
    x = torch.randn(3, 5, generator=gen)
    g = _silent_pair(x, gen)
    h = g.clone()
    h.x = torch.cat([x[:2], torch.randn(1, 5, generator=gen)])  # node 2 alone differs
    loop0 = 0  # node 0's self loop is edge 0
    with torch.no_grad():
        plain, pooled = model(), model(pool=True)
        assert torch.equal(plain(g)[loop0], plain(h)[loop0])
        assert not torch.allclose(pooled(g)[loop0], pooled(h)[loop0])


def test_pooling_is_a_maximum_more_copies_of_a_node_change_nothing():
    gen = torch.Generator().manual_seed(12)
    x = torch.randn(3, 5, generator=gen)
    g = _silent_pair(x, gen)
    h = _silent_pair(torch.cat([x, x[2:]]), gen)  # node 3 repeats node 2
    h.edge_attr = torch.zeros_like(h.edge_attr)
    g.edge_attr = torch.zeros_like(g.edge_attr)
    with torch.no_grad():
        net = model(pool=True)
        torch.testing.assert_close(net(h)[0], net(g)[0])
