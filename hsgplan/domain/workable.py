"""Whether the robot can work in a scene whose fields all read: every reason it cannot, one
line each, said before anything runs (`scene_file.world_of` refuses a scene with any)."""

from __future__ import annotations

from hsgplan.domain.scene import (
    REACH_MAX_XY,
    REACH_MAX_Z,
    ROBOT_BASE,
    ObjectType,
    Rect,
    World,
)


def unworkable(world: World) -> list[str]:
    """Why the robot cannot work in a scene, every reason: a fixture on its base, a surface that
    holds nothing (smaller than a cell, or wholly beyond the arm's reach), a shelf top too high to
    put anything on within reach, an object type that fits on no surface within reach and inside no
    interior, or that would rise past the reach on a surface the planners may put it on
    (`REACH_MAX_Z`: the highest a held object's top may rise; `REACH_MAX_XY`: the farthest the hand
    reaches from the base)."""
    return _on_base(world) + _out_of_reach(world) + _too_high(world)


def _on_base(world: World) -> list[str]:
    base = ROBOT_BASE
    where = f"x {base.x_min} to {base.x_max}, y {base.y_min} to {base.y_max}"
    fixtures = [(f"shelf {s.name!r}", s.outer) for s in world.shelves.values()] + [
        (f"region {name!r}", rect) for name, rect in world.regions.items()
    ]
    return [
        f"{what} stands on the robot's base ({where})" for what, r in fixtures if r.overlaps(base)
    ]


def _out_of_reach(world: World) -> list[str]:
    """Surfaces that hold nothing: narrower than a cell, or every cell beyond the hand's
    horizontal reach."""
    cx, cy = world.cell
    longest = max(world.type_list, key=lambda t: max(t.footprint)).name
    problems = [
        f"{_surface(world, name)} holds no object: it is smaller than a cell of "
        f"{100 * cx:.1f} x {100 * cy:.1f} cm (the scene's largest footprint, {longest}'s, and "
        "its room)"
        for name in world.surfaces
        if not world.grid_cells(name)
    ]
    return problems + [
        f"{_surface(world, name)}: every place on it lies beyond the arm's reach "
        f"({REACH_MAX_XY} m from its base)"
        for name in world.surfaces
        if world.grid_cells(name) and not world.surface_capacity[name]
    ]


def _too_high(world: World) -> list[str]:
    problems = []
    lowest = min(t.height for t in world.type_list)
    high = [s.name for s in world.shelf_list if s.top.z + lowest > REACH_MAX_Z]
    problems += [
        f"shelf {name!r}: its top at {world.shelves[name].top.z:.3f} m leaves no object within "
        f"reach (the lowest stands {lowest:.3f} m; a top may rise to {REACH_MAX_Z} m)"
        for name in high
    ]
    nowhere = [t for t in world.type_list if not _fits_somewhere(world, t)]
    problems += [
        f"object {t.name!r} ({' x '.join(f'{100 * v:.1f}' for v in t.size)} cm) fits on no "
        "surface within reach and inside no shelf"
        for t in nowhere
    ]
    # The symbolic domain lets any object go on any surface: one too tall for the highest
    # surface left would be planned there and held past the reach.
    usable = [n for n in world.surfaces if n not in high]
    top = max(usable, key=lambda n: world.surface_rect(n).z, default=None)
    z = world.surface_rect(top).z if top else 0.0
    problems += [
        f"object {t.name!r} ({t.height:.3f} m high) would rise to {z + t.height:.3f} m on "
        f"{_surface(world, top)} ({z:.3f} m), past the {REACH_MAX_Z} m a held object's top "
        "may rise to (the planners may put any object on any surface)"
        for t in world.type_list
        if top and t not in nowhere and z + t.height > REACH_MAX_Z
    ]
    return problems


def _surface(world: World, name: str) -> str:
    return f"region {name!r}" if name in world.regions else f"the top of shelf {name!r}"


def _fits_somewhere(world: World, t: ObjectType) -> bool:
    def fits(rect: Rect) -> bool:
        return max(t.footprint) <= max(rect.width_x, rect.width_y) and min(t.footprint) <= min(
            rect.width_x, rect.width_y
        )

    on_a_surface = any(
        fits(r) and r.z + t.height <= REACH_MAX_Z
        for r in (world.surface_rect(n) for n in world.surfaces if world.surface_capacity[n])
    )
    return on_a_surface or any(world.fits_inside(t.name, s) for s in world.shelves)
