"""Demonstrations as symbolic trajectories, and copies of them with distractor objects.

The 18 demonstrations name one or two objects, while the planner meets scenes of up to twelve,
with other objects stacked, on shelf tops or inside shelves, and goals with many literals. A
copy of a demonstration adds objects that no action touches: each rests in the same place in
every state (the open space, a shelf top, a prepush region, a shelf's interior, or on another
added object), where the demonstration leaves room for it, and some get goal literals of their
own (a shelf top, shelf A's interior, or stacked on another added object). Nothing in a copy is
taken from evaluation goals: the added objects and their places are drawn here, from a seed.

Why labels carry over: what the demonstrated action needed (its preconditions, the base of a
stack) is the same with the added objects present, and an added object's goal literal is
never something the demonstrated action depends on, so it stays "don't care" in every preimage;
it does teach the network that other goal literals on the same shelf are no dependency, which
the demonstrations alone cannot (their only two-literal goals are stacks).
"""

from __future__ import annotations

import random
from dataclasses import dataclass

from hsgplan.data.demos import Demo
from hsgplan.domain.objects import objects_for_types
from hsgplan.domain.predicates import Literal, Predicate, inside, on
from hsgplan.domain.room import Room, can_carry
from hsgplan.domain.scene import World
from hsgplan.domain.world import MAX_OBJECTS
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph


@dataclass(frozen=True)
class Trajectory:
    """States s_0..s_T of a demonstration, its goal, and the added objects' goal literals."""

    states: tuple[SymbolicSceneGraph, ...]
    goal: frozenset[Literal]
    extra_goal: frozenset[Literal] = frozenset()
    added: tuple[str, ...] = ()

    @property
    def world(self) -> World:
        return self.states[0].world

    @staticmethod
    def of(demo: Demo) -> Trajectory:
        goal = frozenset(lit for lit in demo.goal_literals().literals if lit.positive)
        return Trajectory(tuple(demo.symbolic_states()), goal)


def _places(objects: list[str], states, rng: random.Random) -> list[Literal]:
    """Where each added object rests, unchanged through the trajectory."""
    world = states[0].world
    # what is free in every state at once
    room = Room.left(
        on_top={s: max(len(x.resting_on(s)) for x in states) for s in world.surfaces},
        inside={s: max(len(x.inside(s)) for x in states) for s in world.shelves},
        world=world,
    )
    out = []
    for o in objects:
        options: list[tuple[str, str]] = [("on", s) for s in room.free_tops()]
        options += [("on", b) for b in room.bases()]
        options += [("in", s) for s in room.free_interiors(o)]
        # the open space is where most objects wait, as in the planner's start states
        if room.top["open_space"] > 0 and rng.random() < 0.4:
            options = [("on", "open_space")]
        kind, where = rng.choice(options)
        if kind == "in":
            out.append(inside(o, where))
            room.put_inside(o, where)
        else:
            out.append(on(o, where))
            room.put_on(o, where)
    return out


def _extra_goals(objects: list[str], goal: frozenset[Literal], rng: random.Random, world: World):
    """Goal literals for some added objects, within the capacities the task goal leaves."""
    tops, interior = world.goal_surfaces, world.goal_interior
    # An In literal on shelf A also takes a place of its top here (its last argument is the
    # shelf): stricter than needed, kept so that the copies stay as they were drawn.
    room = Room.left(
        tops,
        () if interior is None else (interior,),
        on_top={s: sum(lit.args[-1] == s for lit in goal) for s in tops},
        inside={interior: sum(lit.predicate is Predicate.IN for lit in goal)} if interior else {},
        world=world,
    )
    out = []
    for o in objects:
        options = [on(o, s) for s in room.free_tops()]
        options += [inside(o, s) for s in room.free_interiors(o)]
        options += [on(o, b) for b in room.bases()]
        if not options or rng.random() < 0.3:
            continue
        lit = rng.choice(options)
        out.append(lit)
        if lit.predicate is Predicate.IN:
            room.put_inside(o, interior)
        else:
            room.put_on(o, lit.args[1])
    return frozenset(out)


def with_distractors(traj: Trajectory, extra: int, rng: random.Random) -> Trajectory:
    """A copy of the trajectory with `extra` added objects (fewer if the scene would overflow)."""
    objects, world = traj.states[0].objects, traj.world
    extra = min(extra, MAX_OBJECTS - len(objects))
    types = [world.type_of(o) for o in objects] + rng.choices(list(world.object_types), k=extra)
    added = list(objects_for_types(types, world)[len(objects) :])
    rng.shuffle(added)
    places = _places(added, traj.states, rng)
    states = tuple(
        SymbolicSceneGraph.from_literals(
            objects + tuple(added),
            [lit for lit in s.literals if lit.predicate is not Predicate.CLEAR] + places,
            world=world,
        )
        for s in traj.states
    )
    return Trajectory(states, traj.goal, _extra_goals(added, traj.goal, rng, world), tuple(added))


def varied(traj: Trajectory, state: SymbolicSceneGraph, rng: random.Random):
    """The state as it is, with an added object in the hand, with an added object put on a
    demonstrated object, or with a demonstrated object moved elsewhere (a quarter each, where
    possible).

    Only for questions whose labels do not depend on where untouched objects are, or on where
    an object is before the step the label is about: preimages (what the demonstrated action
    needed is the same) and reachability (labelled by the transition model). They show the
    network what the demonstrations never do: a held object that is neither the query's
    subject nor its target, whose goal literal is no dependency and which must be put down
    first; a demonstrated object that is not clear; and one that starts on a shelf top or a
    prepush region rather than the open space."""
    roll = rng.random()
    if roll < 1 / 4:
        return state
    if roll < 2 / 4:
        return holding_one(traj, state, rng) or state
    if roll < 3 / 4:
        return covering_one(traj, state, rng) or state
    return relocating_one(traj, state, rng) or state


def _moved(state: SymbolicSceneGraph, o: str, where: Literal) -> SymbolicSceneGraph:
    placements = [
        lit for lit in state.literals if lit.predicate is not Predicate.CLEAR and lit.subject != o
    ]
    return SymbolicSceneGraph.from_literals(state.objects, placements + [where], world=state.world)


def relocating_one(traj: Trajectory, state: SymbolicSceneGraph, rng: random.Random):
    """The state with a clear demonstrated object (resting on a surface, nothing on it) moved
    to another surface with room, or onto a clear added object that can carry it."""
    movable = [
        o
        for o in state.objects
        if o not in traj.added
        and state.holds(Literal(Predicate.CLEAR, (o,)))
        and state.location(o).args[-1] in state.world.surfaces
    ]
    if not movable:
        return None
    o = rng.choice(movable)
    here = state.location(o).args[-1]
    world = state.world
    options = [
        s
        for s in world.surfaces
        if s != here and len(state.resting_on(s)) < world.surface_capacity[s]
    ]
    options += [
        b
        for b in traj.added
        if state.holds(Literal(Predicate.CLEAR, (b,)))
        and can_carry(state.world.type_of(b), state.level(b), state.world)
    ]
    if not options:
        return None
    return _moved(state, o, on(o, rng.choice(options)))


def covering_one(traj: Trajectory, state: SymbolicSceneGraph, rng: random.Random):
    """The state with a clear added object moved onto a clear demonstrated object that can
    carry it, if there is such a pair."""
    demo = [o for o in state.objects if o not in traj.added]
    bases = [
        b
        for b in demo
        if state.holds(Literal(Predicate.CLEAR, (b,)))
        and can_carry(state.world.type_of(b), state.level(b), state.world)
    ]
    tops = [
        o
        for o in traj.added
        if state.holds(Literal(Predicate.CLEAR, (o,))) and not state.resting_on(o)
    ]
    if not bases or not tops:
        return None
    b, o = rng.choice(bases), rng.choice(tops)
    return _moved(state, o, on(o, b))


def holding_one(traj: Trajectory, state: SymbolicSceneGraph, rng: random.Random):
    """The state with one added object in the hand, if the hand is free and one is clear."""
    if state.held() is not None:
        return None
    free = [o for o in traj.added if state.holds(Literal(Predicate.CLEAR, (o,)))]
    if not free:
        return None
    o = rng.choice(free)
    return _moved(state, o, Literal(Predicate.IN_GRASP, (o,)))


def trajectories(demos: list[Demo], copies: int, seed: int) -> list[Trajectory]:
    """Each demonstration, then `copies` copies of each with 1..10 added objects."""
    out = [Trajectory.of(d) for d in demos]
    rng = random.Random(f"augment-{seed}")
    for _ in range(copies):
        for base in out[: len(demos)]:
            out.append(with_distractors(base, rng.randint(1, 10), rng))
    return out
