"""What a scene's sizes allow, said plainly (`hsgplan scenes check FILE`): how many cells each
surface's size makes and how many of them, the cells the arm reaches, it holds; what each
interior holds; the cell each object is counted in and which object sets it, how high a tower
may rise and which object sets that, where each object type fits and whether it carries another.
Read from the `World`, the same properties the transition model, the goal sampler and the PDDL
count with, so the report cannot drift from what the planners are held to."""

from __future__ import annotations

from dataclasses import dataclass

from hsgplan.domain.scene import REACH_MAX_XY, REACH_MAX_Z, SPOT, World


@dataclass(frozen=True)
class SceneLimits:
    surfaces: tuple[tuple[str, ...], ...]  # name, kind, height (m), cells, cells reached, in goals
    interiors: tuple[tuple[str, ...], ...]  # shelf, clearance (m), capacity, what fits
    objects: tuple[tuple[str, ...], ...]  # type, size (cm), carries another, fits inside
    tower: str  # how many objects a tower holds, and why
    cell: str  # the cell each object is counted in, and what sets it


def scene_limits(world: World) -> SceneLimits:
    surfaces = tuple(
        (
            name,
            "region" if name in world.regions else "shelf top",
            f"{world.surface_rect(name).z:.3f}",
            str(len(world.grid_cells(name))),
            str(world.surface_capacity[name]),
            "yes" if name in world.goal_surfaces else "—",
        )
        for name in world.surfaces
    )
    interiors = tuple(
        (
            shelf,
            f"{world.shelves[shelf].clearance:.3f}",
            str(n),
            ", ".join(t.name for t in world.type_list if world.fits_inside(t.name, shelf)) or "—",
        )
        for shelf, n in world.interior_capacity.items()
    )
    objects = tuple(
        (
            t.name,
            " x ".join(f"{100 * v:.1f}" for v in t.size),
            "yes" if world.can_support(t.name) else "no",
            ", ".join(s for s in world.interior_capacity if world.fits_inside(t.name, s)) or "—",
        )
        for t in world.type_list
    )
    return SceneLimits(surfaces, interiors, objects, _tower(world), _cell(world))


def _cell(world: World) -> str:
    cx, cy = world.cell
    widest = max(world.type_list, key=lambda t: min(t.footprint))
    longest = max(world.type_list, key=lambda t: max(t.footprint))
    why = [
        f"{along}: {'the least measured' if c <= SPOT else f'set by {t.name} ({100 * v:.1f} cm)'}"
        for along, c, t, v in (
            ("across", cx, widest, min(widest.footprint)),
            ("along", cy, longest, max(longest.footprint)),
        )
    ]
    return (
        f"each object is counted in a cell of {100 * cx:.1f} x {100 * cy:.1f} cm ({'; '.join(why)}"
        f"); a surface holds its cells within {REACH_MAX_XY} m of the robot's base"
    )


def _tower(world: World) -> str:
    tallest = max(world.type_list, key=lambda t: t.height)
    highest = max(world.surfaces, key=lambda n: world.surface_rect(n).z)
    levels = world.max_tower_levels
    return (
        f"a tower holds at most {levels} object{'s' if levels > 1 else ''}: {levels} of the "
        f"tallest, {tallest.name} ({tallest.height:.3f} m), on the highest surface, {highest} "
        f"({world.surface_rect(highest).z:.3f} m), stay within the {REACH_MAX_Z} m a held "
        "object's top may rise to"
    )
