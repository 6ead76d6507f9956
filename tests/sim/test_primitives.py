"""Each primitive on canonical scenes, and failures as typed outcomes."""

import pytest

from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.parameters import PickParams, PlaceParams, PushParams, nearest_push_bins
from hsgplan.domain.predicates import clear, in_grasp, inside, on
from hsgplan.scene_graph.symbol_mapping import map_symbols
from hsgplan.sim.outcome import Status
from hsgplan.sim.primitives import execute
from hsgplan.sim.scene import Scene

from .conftest import standing


def state(scene):
    return map_symbols(scene.scene_graph()).state


def test_pick_then_place_on_a_shelf_top(scene):
    out = execute(scene, PickParams("cherries"))
    assert out.status is Status.SUCCESS, out.detail
    assert state(scene).holds(in_grasp("cherries"))
    out = execute(scene, PlaceParams("cherries", "shelf_a", 2, 3))
    assert out.status is Status.SUCCESS, out.detail
    s = state(scene)
    assert s.holds(on("cherries", "shelf_a")) and s.held() is None
    assert out.seconds > 0
    # the robot knows where it let go: within a centimetre of where the can came to rest
    body, let_go = scene.robot.released
    assert body == scene.bodies["cherries"]
    rest = scene.pose("cherries").position
    assert max(abs(a - b) for a, b in zip(let_go.position, rest, strict=True)) < 0.01


def test_each_primitive_tells_its_phases_in_order(scene):
    told = []
    assert execute(scene, PickParams("cherries"), on_phase=told.append).ok
    assert told == ["path", "approach", "grasp", "retreat"]
    told.clear()
    assert execute(scene, PlaceParams("cherries", "shelf_a", 2, 3), on_phase=told.append).ok
    assert told == ["path", "approach", "release", "retreat"]
    told.clear()
    angle, dist = nearest_push_bins(0.0, 0.14)
    assert execute(scene, PushParams("tomato_soup", angle, dist), on_phase=told.append).ok
    assert told == ["path", "approach", "push", "retreat"]


def test_stack_a_box_on_a_can(scene):
    assert execute(scene, PickParams("butter")).ok
    out = execute(scene, PlaceParams("butter", "cherries"))
    assert out.status is Status.SUCCESS, out.detail
    s = state(scene)
    assert s.holds(on("butter", "cherries")) and not s.holds(clear("cherries"))


def test_push_a_can_from_prepush_into_the_shelf(scene):
    angle, dist = nearest_push_bins(0.0, 0.14)
    out = execute(scene, PushParams("tomato_soup", angle, dist))
    assert out.status is Status.SUCCESS, out.detail
    assert state(scene).holds(inside("tomato_soup", "shelf_a"))
    # the other objects are where they were
    assert state(scene).holds(on("cherries", "open_space"))


def test_popcorn_upright_is_graspable_and_placeable_on_shelf_b(scene):
    assert execute(scene, PickParams("popcorn")).ok
    out = execute(scene, PlaceParams("popcorn", "shelf_b", 5, 5))
    assert out.status is Status.SUCCESS, out.detail
    assert state(scene).holds(on("popcorn", "shelf_b"))


@pytest.mark.parametrize(
    ("params", "why"),
    [
        (PlaceParams("cherries", "shelf_a", 1, 1), "not held"),
        (PushParams("cherries", 10, 10), "not on a prepush region"),
        (PickParams("alphabet_soup"), "not in the scene"),
        (PlaceParams("cherries", "shelf_a", 1, 12), "outside"),
    ],
)
def test_invalid_parameters_are_typed_outcomes_and_move_nothing(scene, params, why):
    if isinstance(params, PlaceParams) and params.y_bin == 12:
        assert execute(scene, PickParams("cherries")).ok
    before = scene.poses()
    out = execute(scene, params)
    assert out.status is Status.INVALID and why in out.detail
    assert scene.poses().keys() == before.keys()
    for name, pose in before.items():
        assert scene.pose(name).distance(pose) < 1e-6


def test_pick_while_holding_is_invalid(scene):
    assert execute(scene, PickParams("cherries")).ok
    out = execute(scene, PickParams("butter"))
    assert out.status is Status.INVALID and "already holds" in out.detail


def test_out_of_reach_pick_fails_with_no_ik():
    far = Scene(["butter"], seed=0, poses={"butter": standing("butter", 0.95, 0.7)}, world=KITCHEN)
    try:
        out = execute(far, PickParams("butter"))
        assert out.status is Status.NO_IK, out.detail
    finally:
        far.close()
