import pytest

from hsgplan.domain.actions import Pick, Place, Push, parse_action
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.predicates import clear, in_grasp, inside, on
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph as G
from hsgplan.symbolic.transition import InapplicableActionError, applicable_actions, apply, why_not


def state(*literals, objects=None):
    objs = objects or sorted({o for lit in literals for o in lit.objects(KITCHEN)})
    return G.from_literals(objs, literals, world=KITCHEN)


def test_pick_from_a_stack_frees_the_object_below():
    s = state(on("butter", "cherries"), on("cherries", "open_space"))
    s2 = apply(s, Pick("butter"))
    assert s2.holds(in_grasp("butter")) and s2.holds(clear("cherries"))
    assert not s2.holds(on("butter", "cherries")) and not s2.holds(clear("butter"))


def test_pick_preconditions():
    s = state(
        on("butter", "cherries"), on("cherries", "open_space"), inside("tomato_soup", "shelf_a")
    )
    assert "not clear" in why_not(s, Pick("cherries"))
    assert "not clear" in why_not(s, Pick("tomato_soup"))  # inside a shelf
    held = apply(s, Pick("butter"))
    assert "already holds" in why_not(held, Pick("butter"))
    assert "not in the scene" in why_not(s, Pick("popcorn"))


def test_place_on_surfaces_and_objects():
    s = state(in_grasp("butter"), on("cherries", "open_space"), on("popcorn", "open_space"))
    assert apply(s, Place("butter", "shelf_b")).holds(on("butter", "shelf_b"))
    stacked = apply(s, Place("butter", "cherries"))
    assert stacked.holds(on("butter", "cherries")) and not stacked.holds(clear("cherries"))
    assert stacked.held() is None
    assert "cannot carry" in why_not(s, Place("butter", "popcorn"))
    assert "itself" in why_not(s, Place("butter", "butter"))
    assert "not held" in why_not(s, Place("cherries", "shelf_a"))


def test_place_respects_tower_height_and_capacity():
    s = state(in_grasp("butter"), on("cherries", "tomato_soup"), on("tomato_soup", "shelf_a"))
    assert "at most 2" in why_not(s, Place("butter", "cherries"))
    full = [on(f"cherries{'' if k == 1 else f'_{k}'}", "prepush_a") for k in (1, 2)]
    s = state(in_grasp("butter"), *full)
    assert "full" in why_not(s, Place("butter", "prepush_a"))


def test_push_moves_an_object_from_prepush_into_the_shelf():
    s = state(on("cherries", "prepush_a"), on("butter", "open_space"))
    s2 = apply(s, Push("cherries", "shelf_a"))
    assert s2.holds(inside("cherries", "shelf_a")) and not s2.holds(clear("cherries"))
    assert "not on prepush_b" in why_not(s, Push("cherries", "shelf_b"))
    assert "not on prepush_a" in why_not(s, Push("butter", "shelf_a"))


def test_push_preconditions():
    s = state(on("popcorn", "prepush_a"), on("butter", "cherries"), on("cherries", "prepush_a"))
    assert "does not fit" in why_not(s, Push("popcorn", "shelf_a"))
    assert "not clear" in why_not(s, Push("cherries", "shelf_a"))
    inside3 = [inside(f"cherries_{k}", "shelf_a") for k in (2, 3, 4)]
    s = state(on("cherries", "prepush_a"), *inside3)
    assert "full" in why_not(s, Push("cherries", "shelf_a"))
    s = state(on("cherries", "prepush_a"), in_grasp("butter"))
    assert "holds" in why_not(s, Push("cherries", "shelf_a"))


def test_apply_refuses_inapplicable_actions():
    s = state(on("butter", "open_space"))
    with pytest.raises(
        InapplicableActionError, match=r"place\(butter, shelf_a\): 'butter' is not held"
    ):
        apply(s, Place("butter", "shelf_a"))


def test_applicable_actions_are_exactly_those_that_apply():
    s = state(on("butter", "cherries"), on("cherries", "prepush_a"), on("popcorn", "open_space"))
    acts = applicable_actions(s)
    assert set(acts) == {Pick("butter"), Pick("popcorn")}
    held = apply(s, Pick("butter"))
    targets = {a.target for a in applicable_actions(held)}
    assert targets == {"open_space", "prepush_a", "prepush_b", "shelf_a", "shelf_b", "cherries"}
    for a in applicable_actions(held):
        apply(held, a)


def test_parse_action_round_trip():
    for a in (Pick("butter"), Place("butter", "cherries_2"), Push("cherries", "shelf_a")):
        assert parse_action(str(a), world=KITCHEN) == a
