"""Estimates made to rest: a slightly tilted, floating or sunk estimate lands upright on the
support beneath it, stacks bottom first; one far from every support is left alone."""

import math

import numpy as np
import pytest

from hsgplan.domain.kitchen import KITCHEN
from hsgplan.perception.settle import NEAR_TOPS, fits_height, settle, upright
from hsgplan.scene_graph.geometry import Pose, matrix_to_quat


def _tilted(x, y, z, yaw, tilt) -> Pose:
    c, s = math.cos(yaw), math.sin(yaw)
    rz = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])
    rx = np.array(
        [[1, 0, 0], [0, math.cos(tilt), -math.sin(tilt)], [0, math.sin(tilt), math.cos(tilt)]]
    )
    return Pose((x, y, z), matrix_to_quat(rz @ rx))


def _half(t: str) -> float:
    return KITCHEN.object_type(t).size[2] / 2


def test_a_tilted_estimate_is_turned_upright_keeping_its_yaw_and_upside_down_counts_as_up():
    p = upright(_tilted(0.5, 0.0, 0.05, 0.4, math.radians(8)))
    assert p.rotation[2, 2] == pytest.approx(1.0)
    assert math.atan2(p.rotation[1, 0], p.rotation[0, 0]) == pytest.approx(0.4, abs=1e-6)
    flipped = upright(_tilted(0.5, 0.0, 0.05, 0.4, math.pi - math.radians(5)))
    assert flipped.rotation[2, 2] == pytest.approx(1.0)
    lying = _tilted(0.5, 0.0, 0.05, 0.4, math.radians(80))
    assert upright(lying) == lying


def test_an_estimate_over_nothing_is_left_as_it_is():
    beyond = _tilted(1.4, 0.0, 0.3, 0.0, 0.0)  # past the table's far edge
    assert settle(KITCHEN, ["popcorn"], [beyond])[0].position == beyond.position


def test_a_stack_lands_bottom_first_and_a_shelf_top_holds_what_is_near_it():
    types = ["cherries", "butter", "tomato_soup", "popcorn", "alphabet_soup"]
    poses = [
        _tilted(0.5, 0.0, 2 * _half("butter") + _half("cherries") + 0.008, 0.0, 0.05),  # on butter
        _tilted(0.5, 0.005, _half("butter") - 0.008, 0.3, 0.02),  # sunk into the table
        _tilted(
            0.49, 0.38, KITCHEN.shelves["shelf_a"].top.z + _half("tomato_soup") + 0.01, 0.0, 0.0
        ),  # shelf top
        _tilted(0.3, -0.1, _half("popcorn") + 0.2, 0.0, 0.0),  # in the air: nothing floats
        _tilted(0.5, -0.4, _half("alphabet_soup") + 0.005, 0.0, 0.0),  # inside shelf b
    ]
    out = settle(KITCHEN, types, poses)
    assert out[1].position[2] == pytest.approx(_half("butter"))
    assert out[0].position[2] == pytest.approx(2 * _half("butter") + _half("cherries"))
    assert out[2].position[2] == pytest.approx(
        KITCHEN.shelves["shelf_a"].top.z + _half("tomato_soup")
    )
    assert out[3].position[2] == pytest.approx(_half("popcorn"))
    assert out[4].position[2] == pytest.approx(_half("alphabet_soup"))  # not the top above it


def test_a_stacked_object_found_low_rests_on_its_carrier_not_inside_it():
    butter = Pose.from_xyz_yaw(0.5, 0.0, _half("butter"), 0.0)
    top = 2 * _half("butter")
    low = Pose.from_xyz_yaw(0.5, 0.01, top + _half("cherries") - 0.011, 0.0)  # 1.1 cm into it
    _, cherries = settle(KITCHEN, ["butter", "cherries"], [butter, low])
    assert cherries.position[2] == pytest.approx(top + _half("cherries"))
    # a thin box found low enough that its centre is below its carrier's top (a can) still
    # rests on the can, not on the table inside it; one found down at the can's middle fills
    # one space with it (`same_place`), and the can is no carrier of it
    can = Pose.from_xyz_yaw(0.5, 0.0, _half("alphabet_soup"), 0.0)
    can_top = 2 * _half("alphabet_soup")
    for drop, expected in ((0.014, can_top), (0.06, 0.0)):
        box = Pose.from_xyz_yaw(0.5, 0.005, can_top + _half("cream_cheese") - drop, 0.0)
        _, rests = settle(KITCHEN, ["alphabet_soup", "cream_cheese"], [can, box])
        assert rests.position[2] == pytest.approx(expected + _half("cream_cheese")), drop


def test_a_lone_views_estimate_slides_along_its_line_of_sight_onto_the_table():
    eye = np.array([1.15, 0.0, 1.0])
    truth = np.array([0.5, 0.1, _half("butter")])
    direction = (truth - eye) / np.linalg.norm(truth - eye)
    too_near = eye + direction * (np.linalg.norm(truth - eye) - 0.02)  # 2 cm short in depth
    (out,) = settle(KITCHEN, ["butter"], [Pose.from_xyz_yaw(*too_near, 0.2)], [((eye, direction),)])
    assert np.allclose(out.position, truth, atol=1e-9)
    # seen by two views, it sits where they put it and only drops onto the table
    (both,) = settle(
        KITCHEN, ["butter"], [Pose.from_xyz_yaw(*too_near, 0.2)], [((eye, direction),) * 2]
    )
    assert np.allclose(both.position[:2], too_near[:2]) and both.position[2] == truth[2]


def test_where_rays_meet():
    from hsgplan.perception.settle import meeting_point

    point = np.array([0.4, -0.1, 0.05])
    rays = []
    for eye in ([1.0, 0.0, 1.0], [-0.2, 0.7, 0.5], [-0.2, -0.7, 0.5]):
        d = point - np.array(eye)
        rays.append((np.array(eye), d / np.linalg.norm(d)))
    assert np.allclose(meeting_point(rays), point)


def test_between_two_near_tops_the_keypoints_choose():
    butter = Pose.from_xyz_yaw(0.5, 0.0, _half("butter"), 0.0)
    top = 2 * _half("butter")
    # a soup found 1.3 cm low on the butter: its bottom is nearer the table than the butter's top
    low = Pose.from_xyz_yaw(0.5, 0.0, top + _half("alphabet_soup") - 0.013, 0.0)
    types = ["butter", "alphabet_soup"]
    assert settle(KITCHEN, types, [butter, low])[1].position[2] == pytest.approx(
        _half("alphabet_soup")
    )
    on_butter = top + _half("alphabet_soup")

    def cost(centre):  # the views saw it on the butter
        return abs(centre[2] - on_butter)

    rests = settle(KITCHEN, types, [butter, low], None, [lambda c: 0.0, cost])[1]
    assert rests.position[2] == pytest.approx(on_butter)
    # a top farther than `NEAR_TOPS` from its bottom is not a candidate, whatever the cost
    far = Pose.from_xyz_yaw(0.5, 0.0, _half("alphabet_soup") - NEAR_TOPS / 2, 0.0)
    rests = settle(KITCHEN, types, [butter, far], None, [lambda c: 0.0, cost])[1]
    assert rests.position[2] == pytest.approx(_half("alphabet_soup"))


def test_a_centre_a_centimetre_over_the_table_is_no_popcorn():
    thin = np.array([0.5, 0.0, _half("butter")])
    assert fits_height(KITCHEN, KITCHEN.object_type("butter"), thin) and fits_height(
        KITCHEN, KITCHEN.object_type("cream_cheese"), thin
    )
    assert not fits_height(KITCHEN, KITCHEN.object_type("popcorn"), thin) and not fits_height(
        KITCHEN, KITCHEN.object_type("alphabet_soup"), thin
    )
    assert fits_height(
        KITCHEN,
        KITCHEN.object_type("popcorn"),
        np.array([0.5, 0.0, 2 * _half("butter") + _half("popcorn")]),
    )
    on_shelf = np.array([0.49, 0.38, KITCHEN.shelves["shelf_a"].top.z + _half("butter")])
    assert fits_height(KITCHEN, KITCHEN.object_type("butter"), on_shelf) and not fits_height(
        KITCHEN, KITCHEN.object_type("popcorn"), on_shelf
    )
    assert fits_height(
        KITCHEN, KITCHEN.object_type("popcorn"), np.array([1.4, 0.0, 0.01])
    )  # over no surface: no say


def test_nothing_rests_through_an_object_several_views_saw_but_a_lone_views_may_be_a_phantom():
    cheese = Pose.from_xyz_yaw(0.5, 0.0, _half("cream_cheese"), 0.0)
    top = 2 * _half("cream_cheese")
    # a popcorn found 1.1 cm low on the cheese, its keypoints a little surer of the table
    low = Pose.from_xyz_yaw(0.5, 0.0, top + _half("popcorn") - 0.011, 0.0)
    types = ["cream_cheese", "popcorn"]
    costs = [None, lambda centre: centre[2]]
    ray = (np.array([0.5, 0.0, 1.0]), np.array([0.0, 0.0, -1.0]))  # straight down on both
    seen_twice = settle(KITCHEN, types, [cheese, low], [(ray, ray), (ray, ray)], costs)[1]
    assert seen_twice.position[2] == pytest.approx(top + _half("popcorn"))
    seen_once = settle(KITCHEN, types, [cheese, low], [(ray,), (ray, ray)], costs)[1]
    assert seen_once.position[2] == pytest.approx(_half("popcorn"))
    # a neighbour's edge under the centre is no carrier to pass through
    beside = Pose.from_xyz_yaw(0.5 + 0.053 / 2 + 0.005, 0.0, _half("cream_cheese"), 0.0)
    next_to = settle(KITCHEN, types, [beside, low], [(ray, ray), (ray, ray)], costs)[1]
    assert next_to.position[2] == pytest.approx(_half("popcorn"))


def test_an_object_found_twice_a_few_centimetres_apart_is_no_carrier_of_itself():
    from hsgplan.perception.settle import one_level, same_place

    top = KITCHEN.shelves["shelf_b"].top.z + _half("butter")
    near = Pose.from_xyz_yaw(0.555, -0.33, top, 0.0)
    far = Pose.from_xyz_yaw(0.594, -0.33, top - 0.007, 0.0)  # 3.9 cm on along its narrow side
    assert one_level(
        KITCHEN.object_type("butter"), near, KITCHEN.object_type("butter"), far
    ) and not same_place(
        KITCHEN.object_type("butter"),
        near,
        KITCHEN.object_type("butter"),
        far,
    )
    # rested together, neither is carried by the other, even where the keypoints would
    # rather have the nearer one a box up
    one_up = top + 2 * _half("butter")
    costs = [None, lambda centre: abs(centre[2] - one_up)]
    out = settle(KITCHEN, ["butter", "butter"], [far, near], [((), ())] * 2, costs)
    assert [p.position[2] for p in out] == pytest.approx([top, top])
    # one found on the other, a box's height up, is carried
    above = Pose.from_xyz_yaw(0.57, -0.33, one_up - 0.004, 0.0)
    _, rests = settle(KITCHEN, ["butter", "butter"], [near, above], [((), ())] * 2)
    assert not one_level(KITCHEN.object_type("butter"), near, KITCHEN.object_type("butter"), above)
    assert rests.position[2] == pytest.approx(one_up)


def test_estimates_rest_on_the_shelves_and_by_the_sizes_of_the_world_they_are_seen_in():
    from hsgplan.domain.layouts import random_layout

    layout = random_layout(KITCHEN, 3, 0)
    shelf = layout.shelves["shelf_a"]
    assert shelf.top.z != KITCHEN.shelves["shelf_a"].top.z  # another height than the kitchen's
    x, y = (shelf.top.x_min + shelf.top.x_max) / 2, (shelf.top.y_min + shelf.top.y_max) / 2
    soup = layout.object_type("tomato_soup").size[2] / 2
    butter = layout.object_type("butter").size[2]
    found = [
        Pose.from_xyz_yaw(x, y, shelf.top.z + soup + 0.012, 0.0),  # a centimetre afloat
        Pose.from_xyz_yaw(x, y, shelf.top.z + 2 * soup + butter / 2 - 0.006, 0.0),  # sunk in it
    ]
    can, box = settle(layout, ["tomato_soup", "butter"], found)
    assert can.position[2] == pytest.approx(shelf.top.z + soup)
    assert box.position[2] == pytest.approx(shelf.top.z + 2 * soup + butter / 2)
