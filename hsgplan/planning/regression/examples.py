"""Training examples for the task planner's networks, made from the demonstrations.

f_preimage: each demonstration is regressed from its goal backwards, action by action. When the
last action t adds literals the current subgoal g_{t+1} asks for, its preimage g_t is g_{t+1}
without those literals, plus the literals the action consumed (true before it, false after: its
preconditions as the demonstration shows them); an action that adds nothing g_{t+1} asks for
leaves it as it is. The network is asked about one achieved literal at a time (the query), sees
a state s_tau (any state at or before t, as the planner sees the current state while regressing
from far ahead) and g_{t+1}, and learns that literal's preimage (see `preimage_examples`).

f_reach: the literals each demonstrated action adds are reachable in one primitive from the
state before it; negatives are made, as the paper does, by altering those literals: here in
every way (every subject, target and predicate), so that the network also meets, say, a push's
target literal while the object is not yet in front of the shelf. An altered literal can still
be reachable (placing on another surface is one primitive as well), so each is labelled by the
symbolic transition model: reachable if one applicable action makes it true. Examples pair a
state with the demonstrated action's literals and their alterations at once, and with each
candidate alone, as the planner asks about whole subgoals and single literals.

The forward baseline learns, from (s_t, goal), the literals action t adds.
"""

from __future__ import annotations

import random
from dataclasses import dataclass

import torch
from torch_geometric.data import Data

from hsgplan.data.demos import Demo
from hsgplan.domain.objects import EntityKind, kind_of
from hsgplan.domain.predicates import Literal, Predicate
from hsgplan.planning.regression.augment import Trajectory, varied
from hsgplan.planning.regression.encoding import DONT_CARE, FALSE, TRUE, Slots, encode
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.symbolic.transition import applicable_actions, apply


@dataclass(frozen=True)
class Example:
    """An encoded (state, goal) graph, a per-slot target, and which slots are supervised."""

    data: Data
    target: torch.Tensor  # [E, P] long
    mask: torch.Tensor  # [E, P] bool

    def as_data(self) -> Data:
        d = self.data.clone()
        d.target, d.mask = self.target, self.mask
        return d


def _changes(before: SymbolicSceneGraph, after: SymbolicSceneGraph):
    return after.literals - before.literals, before.literals - after.literals


def _trajectory(t: Trajectory | Demo) -> Trajectory:
    return t if isinstance(t, Trajectory) else Trajectory.of(t)


def regressed_subgoals(demo: Trajectory | Demo) -> list[frozenset[Literal]]:
    """g_0 .. g_T: the demonstration's goal regressed through its actions (g_T is the goal)."""
    traj = _trajectory(demo)
    states = traj.states
    goals = [traj.goal]
    for t in range(len(states) - 2, -1, -1):
        added, consumed = _changes(states[t], states[t + 1])
        g = goals[0]
        goals.insert(0, (g - added) | consumed if g & added else g)
    return goals


def _target(data: Data, literals) -> tuple[torch.Tensor, torch.Tensor]:
    slots = Slots(tuple(data.names))
    target = torch.full_like(data.goal, DONT_CARE)
    for lit in literals:
        e, p = slots.slot(lit)
        target[e, p] = TRUE if lit.positive else FALSE
    return target, data.valid.clone()


def preimage_examples(demos: list[Trajectory] | list[Demo], seed: int = 0) -> list[Example]:
    """One example per literal an action achieved for the regressed subgoal (the query), asked
    from every state up to then, in the context of that subgoal. Its preimage: the literals the
    action consumed, the task goal's literals that already held (what had to come first, as a
    stack's base), and no other object in the hand (the previous scene graph's grasp state,
    which the changes alone never show). Added objects' goal literals are context, never
    preimage, and the states asked from are `varied` (see `augment.py`)."""
    rng = random.Random(f"preimage-{seed}")
    out = []
    for traj in map(_trajectory, demos):
        states, goals = traj.states, regressed_subgoals(traj)
        task = goals[-1]
        for t in range(len(states) - 1):
            added, consumed = _changes(states[t], states[t + 1])
            held = states[t].held()
            empty_hand = [
                Literal(Predicate.IN_GRASP, (o,), positive=False)
                for o in states[t].objects
                if o != held
            ]
            for query in sorted(goals[t + 1] & added):
                before = consumed | ((goals[t + 1] - added) & task)
                for tau in range(t + 1):
                    state = varied(traj, states[tau], rng)
                    data = encode(state, goals[t + 1] | traj.extra_goal, [query])
                    out.append(Example(data, *_target(data, sorted(before) + empty_hand)))
    return out


def _alterations(lit: Literal, state: SymbolicSceneGraph) -> set[Literal]:
    objects = state.objects
    out = set()
    for o in objects:  # another subject
        if o not in lit.args:
            out.add(Literal(lit.predicate, (o,) + lit.args[1:]))
    if lit.predicate.arity == 2:  # another target, and the other binary predicate
        for x in state.nodes:
            if x != lit.args[0]:
                out.add(Literal(Predicate.ON, (lit.args[0], x)))
                if kind_of(x) is EntityKind.SHELF:
                    out.add(Literal(Predicate.IN, (lit.args[0], x)))
    else:  # either unary predicate, of any object (grasping another while holding one, say)
        for o in objects:
            out |= {Literal(Predicate.IN_GRASP, (o,)), Literal(Predicate.CLEAR, (o,))}
    out.discard(lit)
    return out


def _every_literal(state: SymbolicSceneGraph) -> set[Literal]:
    out = set()
    for o in state.objects:
        out |= {Literal(Predicate.IN_GRASP, (o,)), Literal(Predicate.CLEAR, (o,))}
        for x in state.nodes:
            if x != o:
                out.add(Literal(Predicate.ON, (o, x)))
                if kind_of(x) is EntityKind.SHELF:
                    out.add(Literal(Predicate.IN, (o, x)))
    return out


def reachable(state: SymbolicSceneGraph) -> set[Literal]:
    """Literals that do not hold now and that one applicable action makes hold (labels, from
    the model): positive ones made true, and negated ones (`not l`) made false."""
    made, undone = set(), set()
    for action in applicable_actions(state):
        after = apply(state, action).literals
        made |= after
        undone |= state.literals - after
    return (made - state.literals) | {lit.negated() for lit in undone}


def reach_examples(demos: list[Trajectory] | list[Demo], seed: int = 0, singles: int = 12):
    """Per demonstrated state: every candidate at once, and up to `singles` reachable and
    `singles` unreachable candidates alone (sampled: a scene of twelve objects has hundreds)."""
    rng = random.Random(f"reach-{seed}")
    out = []
    for traj in map(_trajectory, demos):
        for t in range(len(traj.states) - 1):
            state, after = traj.states[t], traj.states[t + 1]
            if traj.added:  # the demonstrated step still shows, half the time
                state = state if rng.random() < 0.5 else varied(traj, state, rng)
            added, _ = _changes(state, after)
            candidates = set(added)
            for lit in added:
                candidates |= _alterations(lit, state)
            candidates |= _every_literal(state)
            candidates = {c for c in candidates if not state.holds(c)}
            # undoing, too; never both l and not l: one of them holds, and only those that do
            # not hold are candidates
            candidates |= {lit.negated() for lit in state.literals}
            yes = reachable(state)
            pos = sorted(c for c in candidates if c in yes)
            neg = sorted(c for c in candidates if c not in yes)
            chosen = rng.sample(pos, min(singles, len(pos)))
            chosen += rng.sample(neg, min(singles, len(neg)))
            for goal in [candidates] + [{c} for c in chosen]:
                data = encode(state, goal)
                slots = Slots(tuple(data.names))
                target = torch.zeros_like(data.goal)
                mask = torch.zeros_like(data.valid)
                for c in goal:
                    e, p = slots.slot(c)
                    target[e, p] = int(c in yes)
                    mask[e, p] = True
                out.append(Example(data, target, mask))
    return out


def forward_examples(demos: list[Trajectory] | list[Demo]) -> list[Example]:
    """(s_t, goal) -> the literals action t adds: the forward baseline's next subgoal."""
    out = []
    for traj in map(_trajectory, demos):
        states = traj.states
        goal = traj.goal | traj.extra_goal
        for t in range(len(states) - 1):
            added, _ = _changes(states[t], states[t + 1])
            data = encode(states[t], goal)
            out.append(Example(data, *_target(data, added)))
    return out
