"""How much room is left on surfaces, in shelf interiors and on towers while objects are placed.

Why one home: the goal and start-state generator, the motion-task sampler and the augmentation of
demonstrations all draw arrangements object by object, and each must keep within the same limits
(the world's `surface_capacity`, `interior_capacity`, `max_tower_levels`, `can_support`,
`fits_inside`) that the goal validator and the transition model enforce. Kept apart, the three
tallies drifted in small ways (one hard-coded two-level towers); here the limits are counted once.

A `Room` only counts; it draws nothing, so callers keep their own random draws, in their order.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

from hsgplan.domain.scene import World


def can_carry(type_name: str, level: int, world: World) -> bool:
    """Whether an object of this type, `level` objects high in its tower, may take one more."""
    return world.can_support(type_name) and level < world.max_tower_levels


@dataclass
class Room:
    """Free places on some surfaces and in some shelf interiors, and the towers built so far.

    Attributes:
        top: free places on each surface counted (regions and shelf tops), by name.
        interior: free places in each shelf interior counted, by shelf.
        level: each object put on something, 1 on a surface, one more for each object beneath.
        bare: objects, in the order put, that can carry another and have nothing on them yet.
    """

    top: dict[str, int]
    interior: dict[str, int]
    level: dict[str, int] = field(default_factory=dict)
    bare: list[str] = field(default_factory=list)
    world: World = field(kw_only=True)

    @classmethod
    def left(
        cls,
        tops: Iterable[str] | None = None,
        interiors: Iterable[str] | None = None,
        on_top: Mapping[str, int] | None = None,
        inside: Mapping[str, int] | None = None,
        *,
        world: World,
    ) -> Room:
        """The room on `tops` (default: every surface) and in `interiors` (default: every
        shelf's) when `on_top[s]` / `inside[s]` places are taken."""
        on_top, inside = on_top or {}, inside or {}
        tops = world.surfaces if tops is None else tops
        interiors = world.interior_capacity if interiors is None else interiors
        return cls(
            {s: world.surface_capacity[s] - on_top.get(s, 0) for s in tops},
            {s: world.interior_capacity[s] - inside.get(s, 0) for s in interiors},
            world=world,
        )

    def free_tops(self, among: Iterable[str] | None = None) -> list[str]:
        """Counted surfaces with a free place, in the order of `among` (default: as counted)."""
        return [s for s in (self.top if among is None else among) if self.top[s] > 0]

    def free_interiors(self, obj: str) -> list[str]:
        """Counted shelf interiors with a free place that the object fits into."""
        t = self.world.type_of(obj)
        return [s for s in self.interior if self.interior[s] > 0 and self.world.fits_inside(t, s)]

    def bases(self) -> list[str]:
        """Bare objects whose tower may still grow, in the order they were put."""
        return [b for b in self.bare if self.level[b] < self.world.max_tower_levels]

    def put_on(self, obj: str, where: str) -> None:
        """Count `obj` as put on a counted surface or on a bare object."""
        if where in self.top:
            self.top[where] -= 1
            self.level[obj] = 1
        else:
            self.bare.remove(where)
            self.level[obj] = self.level[where] + 1
        if self.world.can_support(self.world.type_of(obj)):
            self.bare.append(obj)

    def put_inside(self, obj: str, shelf: str) -> None:
        """Count `obj` as put inside a shelf; nothing stacks in an interior."""
        self.interior[shelf] -= 1
