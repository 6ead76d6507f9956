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
        for shelf in KITCHEN.shelves:
            assert KITCHEN.fits_inside(name, shelf) == (
                t.height <= KITCHEN.shelves["shelf_a"].clearance
            )
    assert KITCHEN.fits_inside("cherries", "shelf_a")
    assert not KITCHEN.fits_inside("popcorn", "shelf_a")


def test_capacities_hold_a_twelve_object_scene():
    assert KITCHEN.surface_capacity["open_space"] >= world.MAX_OBJECTS
    assert all(c >= 1 for c in KITCHEN.surface_capacity.values())
    assert all(c >= 1 for c in KITCHEN.interior_capacity.values())


def test_tower_limit_keeps_any_tower_within_reach():
    tallest = max(t.height for t in KITCHEN.object_types.values())
    levels = KITCHEN.max_tower_levels
    assert KITCHEN.shelves["shelf_a"].top.z + levels * tallest <= world.REACH_MAX_Z
    assert KITCHEN.shelves["shelf_a"].top.z + (levels + 1) * tallest > world.REACH_MAX_Z


def test_regions_lie_on_the_table_and_do_not_overlap_shelves():
    for name, r in KITCHEN.regions.items():
        assert KITCHEN.table.contains(r.x_min, r.y_min) and KITCHEN.table.contains(r.x_max, r.y_max)
        for s in KITCHEN.shelves.values():
            overlap_x = r.x_min < s.outer.x_max and s.outer.x_min < r.x_max
            overlap_y = r.y_min < s.outer.y_max and s.outer.y_min < r.y_max
            assert not (overlap_x and overlap_y), (name, s.name)
