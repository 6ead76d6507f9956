"""Training examples for the task planner's networks, made from the demonstrations.

f_preimage: each demonstration is regressed from its goal backwards, action by action. When the
last action t adds literals the current subgoal g_{t+1} asks for, its preimage g_t is g_{t+1}
without those literals, plus the literals the action consumed (true before it, false after: its
preconditions as the demonstration shows them); an action that adds nothing g_{t+1} asks for
leaves it as it is. The network is asked about one achieved literal at a time (the query), sees
a state s_tau (any state at or before t, as the planner sees the current state while regressing
from far ahead) and g_{t+1}, and learns that literal's preimage (see `preimage_examples`).

f_reach, two recipes; neither asks the hand-written transition model. Its question: does the
primitive the heuristic names for a literal (`planning/heuristic.py`) make it hold?
- The paper's (`paper_reach_examples`): what each demonstrated step changed is reachable from
  the state before it; altering those literals (every subject, target and predicate) gives the
  unreachable ones.
- Ours (`world_reach_examples`): primitives executed in the simulated world from staged states
  (`hsgplan collect reach`, `data/world_trials.py`) label every literal the heuristic maps to
  the executed action by whether the world shows it afterwards; the demonstrated steps add
  their changes as reachable.
Examples pair a state with all its labelled literals at once, and with each alone, as the
planner asks about single literals.

The forward baseline learns, from (s_t, goal), the literals action t adds.
"""

from __future__ import annotations

import random
from dataclasses import dataclass

import torch
from torch_geometric.data import Data

from hsgplan.data.demos import Demo
from hsgplan.data.world_trials import WorldTrial
from hsgplan.domain.predicates import Literal, Predicate
from hsgplan.domain.scene import EntityKind, World
from hsgplan.planning.heuristic import action_for, candidate_literals
from hsgplan.planning.regression.augment import Trajectory, varied
from hsgplan.planning.regression.encoding import DONT_CARE, FALSE, TRUE, Slots, encode
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph


@dataclass(frozen=True)
class Example:
    """An encoded (state, goal) graph, a per-slot target, and which slots are supervised."""

    data: Data
    target: torch.Tensor  # [E, P] long
    mask: torch.Tensor  # [E, P] bool
    # the world its state was in, where that is not the demonstrations' (a collection of
    # executed primitives staged in other scenes): what features other than names describe
    world: World | None = None

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


def preimage_examples(
    demos: list[Trajectory] | list[Demo], seed: int = 0, vary: bool = True
) -> list[Example]:
    """One example per literal an action achieved for the regressed subgoal (the query), asked
    from every state up to then, in the context of that subgoal. Its preimage: the literals the
    action consumed, the task goal's literals that already held (what had to come first, as a
    stack's base), and no other object in the hand (the previous scene graph's grasp state,
    which the changes alone never show). Added objects' goal literals are context, never
    preimage, and with `vary` the states asked from are `varied` (see `augment.py`)."""
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
                    state = varied(traj, states[tau], rng) if vary else states[tau]
                    data = encode(state, goals[t + 1] | traj.extra_goal, [query])
                    out.append(Example(data, *_target(data, sorted(before) + empty_hand)))
    return out


def _alterations(lit: Literal, state: SymbolicSceneGraph) -> set[Literal]:
    """The paper's negatives: a literal of the next state altered in every way (another
    subject, another target, the other binary predicate, the other unary predicate)."""
    objects = state.objects
    out = set()
    for o in objects:  # another subject
        if o not in lit.args:
            out.add(Literal(lit.predicate, (o,) + lit.args[1:]))
    if lit.predicate.arity == 2:  # another target, and the other binary predicate
        for x in state.nodes:
            if x != lit.args[0]:
                out.add(Literal(Predicate.ON, (lit.args[0], x)))
                if state.world.kind_of(x) is EntityKind.SHELF:
                    out.add(Literal(Predicate.IN, (lit.args[0], x)))
    else:  # either unary predicate, of any object (grasping another while holding one, say)
        for o in objects:
            out |= {Literal(Predicate.IN_GRASP, (o,)), Literal(Predicate.CLEAR, (o,))}
    out.discard(lit)
    return out


def _other_predicates(lit: Literal, state: SymbolicSceneGraph) -> set[Literal]:
    """The paper's words taken narrowly ("altering predicates of edges"): the same edge or
    node under each other predicate (On for In and, towards a shelf, In for On; InGrasp for
    Clear and Clear for InGrasp). The subject and target stay."""
    if lit.predicate.arity == 2:
        a, x = lit.args
        out = {Literal(Predicate.ON, (a, x))}
        if state.world.kind_of(x) is EntityKind.SHELF:
            out.add(Literal(Predicate.IN, (a, x)))
    else:
        out = {Literal(p, lit.args) for p in (Predicate.IN_GRASP, Predicate.CLEAR)}
    out.discard(lit)
    return out


def _labelled(state: SymbolicSceneGraph, labels: dict[Literal, bool]) -> Example:
    data = encode(state, labels)
    slots = Slots(tuple(data.names))
    target = torch.zeros_like(data.goal)
    mask = torch.zeros_like(data.valid)
    for lit, yes in labels.items():
        e, p = slots.slot(lit)
        target[e, p] = int(yes)
        mask[e, p] = True
    return Example(data, target, mask, state.world)


def _examples_of(state: SymbolicSceneGraph, labels: dict[Literal, bool], singles) -> list[Example]:
    """The labels asked all at once, and the chosen ones each alone (as the planner asks)."""
    out = [_labelled(state, labels)]
    out += [_labelled(state, {lit: labels[lit]}) for lit in singles if len(labels) > 1]
    return out


def demonstrated_reach(traj: Trajectory | Demo) -> list[tuple[SymbolicSceneGraph, set[Literal]]]:
    """Per demonstrated step: the state before it and what one primitive changed, as literals
    (those made true, and `not l` for those made false)."""
    traj = _trajectory(traj)
    out = []
    for before, after in zip(traj.states, traj.states[1:], strict=False):
        added, consumed = _changes(before, after)
        out.append((before, added | {lit.negated() for lit in consumed}))
    return out


def paper_reach_examples(
    demos: list[Trajectory] | list[Demo],
    seed: int = 0,
    singles: int = 12,
    predicates_only: bool = False,
):
    """The paper's f_reach labels: what each demonstrated step changed is reachable from the
    state before it; the alterations of what it made true are not (the paper labels them all
    unreachable, though some are: placing on another free surface is one primitive too).
    Alterations change the subject, the target or the predicate, or with `predicates_only` the
    predicate alone (`_other_predicates`). Every label at once, and up to `singles` of each
    class alone."""
    rng = random.Random(f"reach-{seed}")
    alter = _other_predicates if predicates_only else _alterations
    out = []
    for traj in demos:
        for state, changed in demonstrated_reach(traj):
            labels = dict.fromkeys(changed, True)
            for lit in [c for c in changed if c.positive]:
                for alt in alter(lit, state) - changed:
                    if not state.holds(alt):
                        labels[alt] = False
            pos = sorted(c for c, y in labels.items() if y)
            neg = sorted(c for c, y in labels.items() if not y)
            chosen = rng.sample(pos, min(singles, len(pos)))
            chosen += rng.sample(neg, min(singles, len(neg)))
            out += _examples_of(state, labels, chosen)
    return out


def world_labels(trial: WorldTrial) -> dict[Literal, bool]:
    """What one primitive executed in the simulated world says about reachability: each
    literal the heuristic maps to that very action, reached if the primitive succeeded (the
    world checks its intended effect and that nothing else was disturbed) and the literal
    holds in the scene the world shows afterwards. A pick that lifts another object along,
    say, reaches nothing."""
    state, action = trial.state, trial.action
    asked = [lit for lit in candidate_literals(state) if action_for(lit, state) == action]
    return {lit: trial.succeeded and trial.after.holds(lit) for lit in asked}


def world_reach_examples(trials: list[WorldTrial], demos: list[Trajectory] | list[Demo]):
    """Our f_reach labels: every executed primitive's (`world_labels`), and the demonstrated
    steps' changes as reachable. All at once and each alone."""
    out = []
    for trial in trials:
        labels = world_labels(trial)
        if labels:
            out += _examples_of(trial.state, labels, sorted(labels))
    for traj in demos:
        for state, changed in demonstrated_reach(traj):
            labels = dict.fromkeys(changed, True)
            out += _examples_of(state, labels, sorted(labels))
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
