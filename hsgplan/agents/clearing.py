"""Clearing a way: a neighbour moved aside when nothing the task planner names can be done.

The symbolic domain has no action for making room: a box between two tall neighbours leaves
the hand no top-down grasp, a shelf top crowded by earlier places leaves no pose for the next,
and the task planner, whose literals say only where objects rest, names the same doomed pick
again. An agent that checks its actions (`agents/hierarchical.py`) knows this before acting:
every action it was offered failed in its model of the scene. With clearing on, it then tries,
in the same model, moving a neighbour of the blocked action's objects to the open space (picked
and put down where the motion generator proposes), or two one after the other, and takes the
blocked action up again there. The first neighbours after whose moves it plans (a pick
followed by the place the planner means it for, that place too) are moved, each picked and put
down on the open space, and the blocked action is taken next, before the task planner is asked
again (it would put a tower's top back before its base could go).

Only the motion planner in the robot's model answers, as in the checks; no domain rule. What
is read from the observed state: what rests on a neighbour (one that carries another is not
taken from under it) and whether its place is a goal literal already reached (moved only when
no other neighbour will do).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from hsgplan.domain.actions import Action, Pick, Place, push_after
from hsgplan.domain.goals import Goal
from hsgplan.domain.parameters import PrimitiveParams
from hsgplan.domain.scene import OPEN_SPACE
from hsgplan.motion.interface import Feasibility
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph

# m between centres: the hand is about 20 cm long across its fingers and an object half as
# wide again, so a neighbour farther off does not stand in the way of a top-down grasp. Set
# from the hand's size, not tuned.
CLEAR_RADIUS = 0.25
CLEAR_CANDIDATES = 3  # neighbours tried per blocked action, nearest first (a budget)
CLEAR_DEPTH = 2  # neighbours moved aside, at most, before the blocked action must plan
CLEARINGS = 3  # per episode, so that two crowded spots cannot trade objects to the step limit

Propose = Callable[[GeometricSceneGraph, Action, Action | None], PrimitiveParams | None]


@dataclass(frozen=True)
class Clearing:
    """Neighbours to move aside, in turn (each picked, then put down on `target`), before
    `action` (with `following`, the action it is for) is taken up again."""

    moves: tuple[str, ...]
    action: Action
    following: Action | None
    target: str = OPEN_SPACE


def neighbours(
    sg: GeometricSceneGraph,
    state: SymbolicSceneGraph,
    goal: Goal,
    action: Action,
    following: Action | None,
    moved: tuple[str, ...] = (),
) -> list[str]:
    """Objects that may stand in the way of `action` (and of the place it is for), nearest
    first: within CLEAR_RADIUS of its object or of an object it is put on, carrying nothing
    (once the objects `moved` aside are gone) and not held; those resting where a reached goal
    literal says come last (the planner puts them back, but the move undoes part of the goal)."""
    around = [action.obj]
    target = getattr(following, "target", None) or getattr(action, "target", None)
    if target in sg.objects:
        around.append(target)
    order: dict[str, tuple[bool, float]] = {}
    for o in sg.objects:
        if o in around or o in moved or o == sg.held:
            continue
        if any(top not in moved for top in state.resting_on(o)):
            continue
        d = min(_xy_distance(sg, o, a) for a in around)
        if d <= CLEAR_RADIUS:
            order[o] = (state.location(o) in goal.literals, d)
    return sorted(order, key=lambda o: (order[o], o))[:CLEAR_CANDIDATES]


def _xy_distance(sg: GeometricSceneGraph, a: str, b: str) -> float:
    pa, pb = sg.pose(a).position, sg.pose(b).position
    return math.hypot(pa[0] - pb[0], pa[1] - pb[1])


def find_clearing(
    sg: GeometricSceneGraph,
    state: SymbolicSceneGraph,
    goal: Goal,
    blocked: list[tuple[Action, Action | None]],
    propose: Propose,
    feasible: Feasibility,
) -> Clearing | None:
    """The first neighbours (one, or up to CLEAR_DEPTH one after the other: a tower's top and
    then its base, or one neighbour on each side of a box) whose moves to the open space let a
    `blocked` action (with the action it is for) plan, tried in order in a trial of the model;
    None if none do or the model takes no trials."""
    trial_of = getattr(feasible, "trial", None)
    if trial_of is None or sg.held is not None:
        return None
    with trial_of() as trial:
        for action, following in blocked:

            def clear(moved: tuple[str, ...], action=action, following=following):
                """Moves that, after `moved`, unblock the action (none needed: ())."""
                if moved and _plans(trial, sg, action, following, propose, feasible):
                    return ()
                if len(moved) >= CLEAR_DEPTH:
                    return None
                here = trial.scene_graph()
                for n in neighbours(here, state, goal, action, following, moved):
                    rest = _aside_and(
                        trial, here, n, propose, feasible, lambda n=n: clear((*moved, n))
                    )
                    if rest is not None:
                        return (n, *rest)
                return None

            moves = clear(())
            if moves:
                return Clearing(moves, action, following)
    return None


def _aside_and(trial, sg, n, propose, feasible, then: Callable[[], tuple | None]):
    """In the trial: pick `n`, put it on the open space, and `then()` (None where a move fails);
    the trial back as it was."""
    mark = trial.mark()
    try:
        pick = propose(sg, Pick(n), None)
        if pick is None or not feasible(pick) or not trial.run(pick).ok:
            return None
        place = propose(trial.scene_graph(), Place(n, OPEN_SPACE), None)
        if place is None or not feasible(place) or not trial.run(place).ok:
            return None
        return then()
    finally:
        trial.back(mark)


def _plans(trial, sg, action, following, propose, feasible) -> bool:
    """Whether `action` plans in the trial as it is now and, for a pick with a place to follow,
    that place plans once the pick is done; the trial back as it was."""
    params = propose(trial.scene_graph(), action, following)
    if params is None or not feasible(params):
        return False
    if not isinstance(action, Pick) or following is None:
        return True
    mark = trial.mark()
    try:
        return follows(trial, params, following, propose, feasible, sg.world)
    finally:
        trial.back(mark)


def follows(trial, pick: PrimitiveParams, following: Action, propose: Propose, feasible, world):
    """Whether the pick runs in the trial and `following` then plans; the trial is left after
    the pick (the caller takes it back)."""
    if not trial.run(pick).ok:
        return False
    then = propose(trial.scene_graph(), following, push_after(following, world))
    return then is not None and feasible(then)
