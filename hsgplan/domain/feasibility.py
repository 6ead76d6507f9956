"""Which sets of literals a scene can satisfy at once.

One checker serves goals (partial descriptions) and states (complete ones): a contradiction or
a physically impossible demand raises `InfeasibleError` naming the literals and the reason.
The physical rules are the world's derived limits, the same ones the transition model and the
PDDL domain enforce, so a goal that passes here is one the planners can reach.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Iterable

from hsgplan.domain.errors import InfeasibleError
from hsgplan.domain.predicates import Literal, Predicate
from hsgplan.domain.scene import MAX_OBJECTS, REACH_MAX_Z, EntityKind, World


def _q(*lits: Literal) -> str:
    return " and ".join(f"'{lit}'" for lit in lits)


def check_literals(literals: Iterable[Literal], limits: bool = True, *, world: World) -> None:
    """Raise InfeasibleError if no scene satisfies all the literals together.

    With `limits=False` only the structure is checked (one place per object, one object held,
    one object per carrier, no cycles, Clear agreeing), not the world's physical limits
    (capacities, tower height, what fits or carries): an observed scene is a fact even when
    physics put it past a limit the planners respect.
    """
    lits = set(literals)
    pos = {lit for lit in lits if lit.positive}
    for lit in lits:
        if not lit.positive and lit.atom in pos:
            raise InfeasibleError(f"{_q(lit.atom, lit)}: a literal cannot be both true and false")
    objects = {o for lit in lits for o in lit.objects(world)}
    if len(objects) > MAX_OBJECTS:
        raise InfeasibleError(f"{len(objects)} objects named; a scene holds at most {MAX_OBJECTS}")
    place = _placements(pos)
    _check_grasp_and_clear(pos, place)
    carried = _check_stacks(pos, place, limits, world)
    if limits:
        _check_capacity(pos, world)
        _check_shelves(pos, carried, world)


def _placements(pos: set[Literal]) -> dict[str, Literal]:
    place: dict[str, Literal] = {}
    for lit in sorted(pos):
        if lit.predicate is Predicate.CLEAR:
            continue
        if lit.predicate is Predicate.ON and lit.args[0] == lit.args[1]:
            raise InfeasibleError(f"'{lit}': an object cannot rest on itself")
        o = lit.subject
        if o in place:
            raise InfeasibleError(f"{_q(place[o], lit)}: an object is in one place at a time")
        place[o] = lit
    return place


def _check_grasp_and_clear(pos: set[Literal], place: dict[str, Literal]) -> None:
    held = sorted(lit for lit in place.values() if lit.predicate is Predicate.IN_GRASP)
    if len(held) > 1:
        raise InfeasibleError(f"{_q(held[0], held[1])}: the gripper holds one object at a time")
    for lit in sorted(pos):
        if lit.predicate is not Predicate.CLEAR:
            continue
        o = lit.subject
        where = place.get(o)
        if where is not None and where.predicate is Predicate.IN_GRASP:
            raise InfeasibleError(f"{_q(lit, where)}: a held object is not clear")
        if where is not None and where.predicate is Predicate.IN:
            raise InfeasibleError(
                f"{_q(lit, where)}: an object inside a shelf can be neither grasped nor stacked "
                "on, so it is never clear"
            )
        for other in place.values():
            if other.predicate is Predicate.ON and other.args[1] == o:
                raise InfeasibleError(f"{_q(lit, other)}: something rests on '{o}'")


def _check_stacks(
    pos: set[Literal], place: dict[str, Literal], limits: bool, world: World
) -> dict[str, Literal]:
    """Check every object-on-object literal; return, per carrier, the literal that loads it."""
    carried: dict[str, Literal] = {}
    for lit in sorted(place.values()):
        if lit.predicate is not Predicate.ON or world.kind_of(lit.args[1]) is not EntityKind.OBJECT:
            continue
        base = lit.args[1]
        if base in carried:
            raise InfeasibleError(f"{_q(carried[base], lit)}: an object carries at most one other")
        carried[base] = lit
        t = world.object_type(base)
        if limits and not world.can_support(t.name):
            raise InfeasibleError(
                f"'{lit}': the top of {base} ({100 * t.top_face_min_side:.1f} cm wide) is too "
                "narrow to carry anything"
            )
        below = place.get(base)
        if below is not None and below.predicate is Predicate.IN_GRASP:
            raise InfeasibleError(f"{_q(lit, below)}: a held object carries nothing")
    for o in place:
        chain = [o]
        while (nxt := _below(place, chain[-1], world)) is not None:
            if nxt in chain:
                cycle = chain[chain.index(nxt) :]
                raise InfeasibleError(
                    f"{_q(*(place[c] for c in cycle))}: the objects stack in a cycle"
                )
            chain.append(nxt)
        if limits and len(chain) > world.max_tower_levels:
            tower = " on ".join(chain)
            raise InfeasibleError(
                f"'{place[o]}': the tower {tower} is {len(chain)} objects high; towers hold at "
                f"most {world.max_tower_levels} so that none rises past the arm's reach "
                f"({100 * REACH_MAX_Z:.0f} cm above the table)"
            )
    return carried


def _below(place: dict[str, Literal], o: str, world: World) -> str | None:
    lit = place.get(o)
    if lit and lit.predicate is Predicate.ON and world.kind_of(lit.args[1]) is EntityKind.OBJECT:
        return lit.args[1]
    return None


def _check_capacity(pos: set[Literal], world: World) -> None:
    on_surface: dict[str, list[Literal]] = defaultdict(list)
    in_shelf: dict[str, list[Literal]] = defaultdict(list)
    for lit in sorted(pos):
        if lit.predicate is Predicate.ON and world.kind_of(lit.args[1]) is not EntityKind.OBJECT:
            on_surface[lit.args[1]].append(lit)
        elif lit.predicate is Predicate.IN:
            in_shelf[lit.args[1]].append(lit)
    for surface, lits in on_surface.items():
        if len(lits) > world.surface_capacity[surface]:
            where = f"{surface}'s top" if surface in world.shelves else surface
            raise InfeasibleError(
                f"'{lits[-1]}': {len(lits)} objects on {where}, which holds at most "
                f"{world.surface_capacity[surface]}"
            )
    for shelf, lits in in_shelf.items():
        room = world.interior_capacity.get(shelf)
        if room is None:
            raise InfeasibleError(f"'{lits[-1]}': {shelf} has no interior")
        if len(lits) > room:
            raise InfeasibleError(
                f"'{lits[-1]}': {len(lits)} objects inside {shelf}, whose interior holds at most "
                f"{room}"
            )


def _check_shelves(pos: set[Literal], carried: dict[str, Literal], world: World) -> None:
    for lit in sorted(pos):
        if lit.predicate is not Predicate.IN:
            continue
        o, shelf = lit.args
        t = world.object_type(o)
        if not world.fits_inside(t.name, shelf):
            raise InfeasibleError(
                f"'{lit}': {o} ({100 * t.height:.1f} cm tall as it rests) does not fit into "
                f"{shelf}'s interior ({100 * world.shelves[shelf].clearance:.1f} cm clearance)"
            )
        if o in carried:
            raise InfeasibleError(
                f"{_q(lit, carried[o])}: nothing can be stacked on an object inside a shelf "
                "(the shelf's top board is in the way)"
            )
