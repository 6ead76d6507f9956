"""The symbolic transition model: preconditions and effects of pick, place and push.

The PDDL domain in `pddl.py` states the same rules for Fast Downward; tests replay its plans
here step by step. Limits (capacities, tower height, which objects carry others or fit into a
shelf) come from `world.py`.
"""

from __future__ import annotations

from hsgplan.domain.actions import Action, Pick, Place, Push
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.objects import object_type
from hsgplan.domain.predicates import Literal, Predicate, in_grasp, inside, on
from hsgplan.domain.world import (
    INTERIOR_CAPACITY,
    MAX_TOWER_LEVELS,
    SHELVES,
    SURFACE_CAPACITY,
    SURFACES,
    can_support,
    fits_inside,
)
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph


class InapplicableActionError(InvalidInputError):
    """An action whose preconditions do not hold in the state it is applied to."""


def why_not(state: SymbolicSceneGraph, action: Action) -> str | None:
    """None if the action is applicable in the state, else the unmet precondition."""
    if action.obj not in state.objects:
        return f"'{action.obj}' is not in the scene"
    held = state.held()
    if isinstance(action, Pick):
        if held is not None:
            return f"the gripper already holds '{held}'"
        if not state.holds(Literal(Predicate.CLEAR, (action.obj,))):
            return f"'{action.obj}' is not clear"
        return None
    if isinstance(action, Place):
        return _why_not_place(state, action, held)
    return _why_not_push(state, action, held)


def _why_not_place(state: SymbolicSceneGraph, action: Place, held: str | None) -> str | None:
    o, t = action.obj, action.target
    if held != o:
        return f"'{o}' is not held"
    if t in SURFACES:
        if len(state.resting_on(t)) >= SURFACE_CAPACITY[t]:
            return f"'{t}' is full ({SURFACE_CAPACITY[t]} objects)"
        return None
    if t not in state.objects:
        return f"'{t}' is neither a surface nor an object in the scene"
    if t == o:
        return "an object cannot be placed on itself"
    if not can_support(object_type(t).name):
        return f"'{t}' cannot carry another object"
    if not state.holds(Literal(Predicate.CLEAR, (t,))):
        return f"'{t}' is not clear"
    if state.level(t) + 1 > MAX_TOWER_LEVELS:
        return f"a tower may hold at most {MAX_TOWER_LEVELS} objects"
    return None


def _why_not_push(state: SymbolicSceneGraph, action: Push, held: str | None) -> str | None:
    o, s = action.obj, action.shelf
    if s not in SHELVES:
        return f"'{s}' is not a shelf"
    if held is not None:
        return f"the gripper holds '{held}'"
    if state.location(o) != on(o, SHELVES[s].prepush):
        return f"'{o}' is not on {SHELVES[s].prepush}"
    if not state.holds(Literal(Predicate.CLEAR, (o,))):
        return f"'{o}' is not clear"
    if not fits_inside(object_type(o).name, s):
        return f"'{o}' does not fit into {s}"
    if len(state.inside(s)) >= INTERIOR_CAPACITY[s]:
        return f"{s}'s interior is full ({INTERIOR_CAPACITY[s]} objects)"
    return None


def apply(state: SymbolicSceneGraph, action: Action) -> SymbolicSceneGraph:
    """The state after the action; raises InapplicableActionError if a precondition fails."""
    reason = why_not(state, action)
    if reason is not None:
        raise InapplicableActionError(f"{action}: {reason}")
    o = action.obj
    placements = {
        lit for lit in state.literals if lit.predicate is not Predicate.CLEAR and lit.subject != o
    }
    if isinstance(action, Pick):
        placements.add(in_grasp(o))
    elif isinstance(action, Place):
        placements.add(on(o, action.target))
    else:
        placements.add(inside(o, action.shelf))
    return SymbolicSceneGraph.from_literals(state.objects, placements)


def applicable_actions(state: SymbolicSceneGraph) -> list[Action]:
    """Every action whose preconditions hold, in a fixed order."""
    held = state.held()
    candidates: list[Action]
    if held is not None:
        targets = list(SURFACES) + [x for x in state.objects if x != held]
        candidates = [Place(held, t) for t in targets]
    else:
        candidates = [Pick(o) for o in state.objects]
        candidates += [Push(o, s) for o in state.objects for s in SHELVES]
    return [a for a in candidates if why_not(state, a) is None]
