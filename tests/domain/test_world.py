from hsgplan.domain import world
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.world import Kind


def test_every_object_is_graspable_and_distinctly_coloured():
    for t in KITCHEN.object_types.values():
        assert t.grasp_width <= world.GRIPPER_MAX_OPENING, t.name
    colours = [t.color for t in KITCHEN.object_types.values()]
    assert len(set(colours)) == len(colours)


def test_the_paper_objects_three_cans_three_boxes():
    kinds = sorted(t.kind for t in KITCHEN.object_types.values())
    assert kinds.count(Kind.CAN) == 3 and kinds.count(Kind.BOX) == 3


def test_cans_fit_inside_shelves_and_upright_popcorn_does_not():
    for name, t in KITCHEN.object_types.items():
        for shelf in world.SHELVES:
            assert world.fits_inside(name, shelf) == (t.height <= world.SHELF_CLEARANCE)
    assert world.fits_inside("cherries", "shelf_a")
    assert not world.fits_inside("popcorn", "shelf_a")


def test_capacities_hold_a_twelve_object_scene():
    assert world.SURFACE_CAPACITY["open_space"] >= world.MAX_OBJECTS
    assert all(c >= 1 for c in world.SURFACE_CAPACITY.values())
    assert all(c >= 1 for c in world.INTERIOR_CAPACITY.values())


def test_tower_limit_keeps_any_tower_within_reach():
    tallest = max(t.height for t in KITCHEN.object_types.values())
    levels = world.MAX_TOWER_LEVELS
    assert world.SHELF_TOP_Z + levels * tallest <= world.REACH_MAX_Z
    assert world.SHELF_TOP_Z + (levels + 1) * tallest > world.REACH_MAX_Z


def test_regions_lie_on_the_table_and_do_not_overlap_shelves():
    for name, r in world.REGIONS.items():
        assert world.TABLE.contains(r.x_min, r.y_min) and world.TABLE.contains(r.x_max, r.y_max)
        for s in world.SHELVES.values():
            overlap_x = r.x_min < s.outer.x_max and s.outer.x_min < r.x_max
            overlap_y = r.y_min < s.outer.y_max and s.outer.y_min < r.y_max
            assert not (overlap_x and overlap_y), (name, s.name)
