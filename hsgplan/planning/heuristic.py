"""The paper's heuristic from an immediate subgoal to a primitive and its object.

It reads the observed symbolic state (what rests on what, what is held) and nothing else: no
preconditions are checked here. Whether the action it names can achieve the literal is what
f_reach learns; when it cannot, the world says so (a primitive fails, or in the symbolic loop
the state stays as it was and the step is wasted).
"""

from __future__ import annotations

from hsgplan.domain.actions import Action, Pick, Place, Push
from hsgplan.domain.predicates import Literal, Predicate
from hsgplan.domain.scene import EntityKind
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph


def buffer_region(state: SymbolicSceneGraph) -> str:
    """Where an object that must leave the hand is put down: the open space, the region a
    scene lists first."""
    return next(iter(state.world.regions))


def action_for(lit: Literal, state: SymbolicSceneGraph) -> Action | None:
    """The primitive and object that are meant to make `lit` hold from `state`, or None where
    no primitive is meant to (a negated `Clear` or `In`, or `Clear` of a bare object)."""
    if lit.positive:
        if lit.predicate is Predicate.IN_GRASP:
            return Pick(lit.subject)
        if lit.predicate is Predicate.ON:
            return Place(*lit.args)
        if lit.predicate is Predicate.IN:
            return Push(*lit.args)
        # Clear(x): lift what rests on x (x in the hand is cleared by placing it where the rest
        # of the subgoal wants it, not by dropping it anywhere)
        above = state.resting_on(lit.subject)
        return Pick(above[0]) if above else None
    if lit.predicate is Predicate.IN_GRASP:  # let go of it
        return Place(lit.subject, buffer_region(state))
    if lit.predicate is Predicate.ON:  # take it off
        return Pick(lit.subject)
    return None


def candidate_literals(state: SymbolicSceneGraph) -> list[Literal]:
    """Every literal over the state's nodes that does not hold and that `action_for` maps to a
    primitive: what a planner may ask f_reach about. Sorted, so the order is reproducible."""
    out: set[Literal] = set()
    for o in state.objects:
        out |= {Literal(Predicate.IN_GRASP, (o,)), Literal(Predicate.CLEAR, (o,))}
        for x in state.nodes:
            if x == o:
                continue
            out.add(Literal(Predicate.ON, (o, x)))
            if state.world.kind_of(x) is EntityKind.SHELF:
                out.add(Literal(Predicate.IN, (o, x)))
    out = {lit for lit in out if not state.holds(lit)}
    out |= {lit.negated() for lit in state.literals}
    return sorted(lit for lit in out if action_for(lit, state) is not None)
