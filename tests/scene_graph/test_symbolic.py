import pytest
import torch

from hsgplan.domain.errors import InfeasibleError
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.predicates import PREDICATES, Predicate, clear, in_grasp, inside, on
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph


def _stack_scene():
    return SymbolicSceneGraph.from_literals(
        ["butter", "cherries", "tomato_soup", "popcorn"],
        [
            on("butter", "cherries"),
            on("cherries", "shelf_a"),
            inside("tomato_soup", "shelf_a"),
            in_grasp("popcorn"),
        ],
        world=KITCHEN,
    )


def test_clear_is_derived():
    s = _stack_scene()
    assert s.holds(clear("butter"))
    assert not s.holds(clear("cherries"))  # butter rests on it
    assert not s.holds(clear("tomato_soup"))  # inside a shelf
    assert not s.holds(clear("popcorn"))  # held
    assert s.held() == "popcorn"
    assert s.level("butter") == 2 and s.level("cherries") == 1 and s.level("popcorn") == 0


def test_equality_and_hash_ignore_input_order():
    a = SymbolicSceneGraph.from_literals(
        ["cherries", "butter"],
        [on("butter", "shelf_a"), on("cherries", "open_space")],
        world=KITCHEN,
    )
    b = SymbolicSceneGraph.from_literals(
        ["butter", "cherries"],
        [on("cherries", "open_space"), on("butter", "shelf_a")],
        world=KITCHEN,
    )
    c = SymbolicSceneGraph.from_literals(
        ["butter", "cherries"],
        [on("cherries", "open_space"), on("butter", "shelf_b")],
        world=KITCHEN,
    )
    assert a == b and hash(a) == hash(b)
    assert a != c
    a.location("butter")  # filling the lookup cache must not change equality
    assert a == b and len({a, b, c}) == 2


def test_text_forms():
    s = _stack_scene()
    assert str(s) == (
        "On(cherries, shelf_a) & In(tomato_soup, shelf_a) & InGrasp(popcorn) & "
        "On(butter, cherries) & Clear(butter)"
    )
    lines = s.to_text().splitlines()
    assert lines[0].split() == ["cherries", "-On->", "shelf_a"]
    assert lines[-1].split() == ["butter", "-On->", "cherries", "[Clear]"]


def test_given_clear_must_agree():
    with pytest.raises(InfeasibleError, match="cannot hold"):
        SymbolicSceneGraph.from_literals(
            ["butter", "cherries"],
            [on("butter", "cherries"), on("cherries", "shelf_a"), clear("cherries")],
            world=KITCHEN,
        )


@pytest.mark.parametrize(
    "literals",
    [
        [on("butter", "shelf_a")],  # cherries has no placement
        [on("butter", "shelf_a"), on("cherries", "shelf_a"), on("cherries", "open_space")],
        [in_grasp("butter"), in_grasp("cherries")],
        [on("butter", "cherries"), on("cherries", "butter")],
        [on("butter", "cherries"), in_grasp("cherries")],
        [on("butter", "shelf_a"), on("cherries", "tomato_soup")],  # tomato_soup not in the scene
    ],
)
def test_inconsistent_states_are_refused(literals):
    with pytest.raises(InfeasibleError):
        SymbolicSceneGraph.from_literals(["butter", "cherries"], literals, world=KITCHEN)


def test_to_data_shapes_and_edges():
    s = _stack_scene()
    data = s.to_data()
    n = len(s.objects) + len(KITCHEN.fixtures)
    assert data.x.shape == (n, len(KITCHEN.entity_types))
    assert torch.equal(data.x.sum(1), torch.ones(n))
    assert data.edge_attr.shape == (data.edge_index.shape[1], len(PREDICATES))
    assert data.names == list(s.objects) + list(KITCHEN.fixtures)
    edges = {
        (data.names[i], data.names[j], PREDICATES[k])
        for (i, j), row in zip(data.edge_index.t().tolist(), data.edge_attr.tolist(), strict=True)
        for k, v in enumerate(row)
        if v
    }
    assert edges == {
        ("butter", "cherries", Predicate.ON),
        ("cherries", "shelf_a", Predicate.ON),
        ("tomato_soup", "shelf_a", Predicate.IN),
        ("popcorn", "popcorn", Predicate.IN_GRASP),
        ("butter", "butter", Predicate.CLEAR),
    }


def test_duplicate_instances_share_a_node_type():
    s = SymbolicSceneGraph.initial(["cherries", "cherries_2"], world=KITCHEN)
    data = s.to_data()
    assert torch.equal(data.x[0], data.x[1])
    assert data.x[0, KITCHEN.entity_types.index("cherries")] == 1


def test_observed_scenes_may_break_planning_limits_but_not_structure():
    tower = [on("butter", "cherries"), on("cherries", "tomato_soup"), on("tomato_soup", "shelf_a")]
    objs = ["butter", "cherries", "tomato_soup"]
    with pytest.raises(InfeasibleError, match="towers hold at most"):
        SymbolicSceneGraph.from_literals(objs, tower, world=KITCHEN)
    observed = SymbolicSceneGraph.from_literals(objs, tower, limits=False, world=KITCHEN)
    assert observed.level("butter") == 3
    with pytest.raises(InfeasibleError, match="one place"):
        SymbolicSceneGraph.from_literals(
            ["butter"],
            [on("butter", "shelf_a"), on("butter", "shelf_b")],
            limits=False,
            world=KITCHEN,
        )
