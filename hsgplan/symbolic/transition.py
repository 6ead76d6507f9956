"""The symbolic transition model: preconditions and effects of pick, place and push.

The PDDL domain in `pddl.py` states the same rules for Fast Downward; tests replay its plans
here step by step. Limits (capacities, tower height, which objects carry others or fit into a
shelf) come from the state's world.
"""

from __future__ import annotations

from hsgplan.domain.actions import Action, Pick, Place, Push
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.predicates import Literal, Predicate, in_grasp, inside, on
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
    o, t, world = action.obj, action.target, state.world
    if held != o:
        return f"'{o}' is not held"
    if t in world.surface_capacity:
        if len(state.resting_on(t)) >= world.surface_capacity[t]:
            return f"'{t}' is full ({world.surface_capacity[t]} objects)"
        return None
    if t not in state.objects:
        return f"'{t}' is neither a surface nor an object in the scene"
    if t == o:
        return "an object cannot be placed on itself"
    if not world.can_support(world.object_type(t).name):
        return f"'{t}' cannot carry another object"
    if not state.holds(Literal(Predicate.CLEAR, (t,))):
        return f"'{t}' is not clear"
    if state.level(t) + 1 > world.max_tower_levels:
        return f"a tower may hold at most {world.max_tower_levels} objects"
    return None


def _why_not_push(state: SymbolicSceneGraph, action: Push, held: str | None) -> str | None:
    o, s, world = action.obj, action.shelf, state.world
    if s not in world.shelves:
        return f"'{s}' is not a shelf"
    if s not in world.interior_capacity:
        return f"'{s}' has no interior"
    if held is not None:
        return f"the gripper holds '{held}'"
    if state.location(o) != on(o, world.shelves[s].prepush):
        return f"'{o}' is not on {world.shelves[s].prepush}"
    if not state.holds(Literal(Predicate.CLEAR, (o,))):
        return f"'{o}' is not clear"
    if not world.fits_inside(world.object_type(o).name, s):
        return f"'{o}' does not fit into {s}"
    if len(state.inside(s)) >= world.interior_capacity[s]:
        return f"{s}'s interior is full ({world.interior_capacity[s]} objects)"
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
    return SymbolicSceneGraph.from_literals(state.objects, placements, world=state.world)


def applicable_actions(state: SymbolicSceneGraph) -> list[Action]:
    """Every action whose preconditions hold, in a fixed order."""
    held = state.held()
    candidates: list[Action]
    if held is not None:
        targets = list(state.world.surfaces) + [x for x in state.objects if x != held]
        candidates = [Place(held, t) for t in targets]
    else:
        candidates = [Pick(o) for o in state.objects]
        candidates += [Push(o, s) for o in state.objects for s in state.world.shelves]
    return [a for a in candidates if why_not(state, a) is None]
