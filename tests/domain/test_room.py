"""The shared tally of free places on surfaces, in interiors and on towers."""

import pytest

from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.room import Room, can_carry


def test_left_counts_capacity_minus_what_is_taken_in_the_order_given():
    room = Room.left(
        ("shelf_b", "shelf_a"), ("shelf_a",), on_top={"shelf_a": 3}, inside={}, world=KITCHEN
    )
    assert list(room.top) == ["shelf_b", "shelf_a"]
    assert room.top == {"shelf_b": KITCHEN.surface_capacity["shelf_b"], "shelf_a": 1}
    assert room.interior == {"shelf_a": KITCHEN.interior_capacity["shelf_a"]}
    assert room.level == {} and room.bare == []


def test_left_defaults_to_every_surface_and_interior():
    room = Room.left(world=KITCHEN)
    assert room.top == KITCHEN.surface_capacity and tuple(room.top) == KITCHEN.surfaces
    assert room.interior == KITCHEN.interior_capacity and tuple(room.interior) == tuple(
        KITCHEN.shelves
    )


def test_a_full_surface_is_no_longer_free():
    room = Room({"shelf_a": 1, "open_space": 2}, {}, world=KITCHEN)
    room.put_on("cherries", "shelf_a")
    assert room.top["shelf_a"] == 0
    assert room.free_tops() == ["open_space"]
    assert room.free_tops(("shelf_a",)) == []
    assert room.free_tops(("open_space", "shelf_a")) == ["open_space"]


def test_towers_grow_only_on_carriers_and_up_to_the_level_limit():
    room = Room({"shelf_a": 4}, {}, world=KITCHEN)
    room.put_on("popcorn", "shelf_a")  # its narrow top carries nothing
    room.put_on("butter", "shelf_a")
    assert room.bases() == ["butter"]
    room.put_on("cherries", "butter")
    assert room.level == {"popcorn": 1, "butter": 1, "cherries": 2}
    assert "butter" not in room.bare  # covered now
    assert room.top["shelf_a"] == 2  # a stacked object takes no place on the surface
    assert KITCHEN.max_tower_levels == 2, "the next line assumes two-level towers"
    assert room.bases() == []  # cherries carries, but its tower is full


def test_bases_keep_the_order_objects_were_put_in():
    room = Room({"open_space": 12}, {}, world=KITCHEN)
    for o in ("tomato_soup", "cherries", "cream_cheese"):
        room.put_on(o, "open_space")
    assert room.bases() == ["tomato_soup", "cherries", "cream_cheese"]


def test_interiors_take_what_fits_until_full_and_hold_no_towers():
    room = Room({}, {"shelf_a": 1, "shelf_b": 0}, world=KITCHEN)
    assert room.free_interiors("cherries_2") == ["shelf_a"]
    assert room.free_interiors("popcorn") == []  # too tall as it rests
    room.put_inside("cherries_2", "shelf_a")
    assert room.interior == {"shelf_a": 0, "shelf_b": 0}
    assert room.free_interiors("cherries") == []
    assert room.bases() == [] and room.level == {}


def test_putting_on_an_object_that_is_not_bare_fails_loudly():
    room = Room({"shelf_a": 4}, {}, world=KITCHEN)
    room.put_on("butter", "shelf_a")
    room.put_on("cherries", "butter")
    with pytest.raises(ValueError):
        room.put_on("alphabet_soup", "butter")


def test_can_carry_needs_a_wide_top_and_a_tower_below_the_limit():
    assert can_carry("butter", 1, world=KITCHEN)
    assert not can_carry("popcorn", 1, world=KITCHEN)
    assert not can_carry("butter", KITCHEN.max_tower_levels, world=KITCHEN)
