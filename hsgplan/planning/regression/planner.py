"""Task planners behind one interface: the learned regression planner, the forward baseline,
and Fast Downward. Each returns the next action for a symbolic state and a goal.

The regression loop (the paper's phi): f_preimage gives the preimage of one goal literal (the
query) in the context of the goal; a goal literal whose preimage names another unsatisfied goal
literal has to wait for it (a stack's top for its base). One of the goal literals free to go is
drawn uniformly (the paper's subgoal serialisation) and regressed: while f_reach says one
primitive does not reach it, it is replaced by an unsatisfied literal of its preimage (a
reachable one when there is one), up to a depth cap. The literal reached is the immediate
subgoal g-hat, and a heuristic names the primitive and object that achieve it.
"""

from __future__ import annotations

import random
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import torch

from hsgplan.domain.goals import Goal
from hsgplan.domain.predicates import Literal, Predicate
from hsgplan.domain.transition import Action, Pick, Place, Push, why_not
from hsgplan.planning.regression.encoding import TRUE, Slots, decode, encode
from hsgplan.planning.regression.train import load_network
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph

MAX_DEPTH = 8
BUFFER = "open_space"


@dataclass(frozen=True)
class TaskDecision:
    """The next action (None with a reason when there is none), the subgoal it serves, and the
    time the decision took."""

    action: Action | None
    subgoal: Literal | None
    seconds: float
    note: str = ""


class TaskPlanner(Protocol):
    name: str

    def next_action(self, state: SymbolicSceneGraph, goal: Goal) -> TaskDecision: ...


def action_for(lit: Literal, state: SymbolicSceneGraph) -> Action | None:
    """The primitive and object that achieve one literal, if one does from this state."""
    held = state.held()
    if lit.positive:
        if lit.predicate is Predicate.IN_GRASP:
            options = [Pick(lit.subject)]
        elif lit.predicate is Predicate.ON:
            options = [Place(*lit.args)]
        elif lit.predicate is Predicate.IN:
            options = [Push(*lit.args)]
        else:  # Clear(x): lift what rests on x, or put x down
            options = [Pick(o) for o in state.resting_on(lit.subject)]
            options += [Place(lit.subject, BUFFER)] if held == lit.subject else []
    elif lit.predicate is Predicate.IN_GRASP:  # let go of it
        options = [Place(lit.subject, BUFFER)]
    elif lit.predicate is Predicate.ON:  # take it off
        options = [Pick(lit.subject)]
    else:
        options = []
    return next((a for a in options if why_not(state, a) is None), None)


class RegressionPlanner:
    """The learned regression planner, from a checkpoint folder made by `hsgplan train task`."""

    name = "regression"

    def __init__(self, checkpoint: Path, seed: int = 0, max_depth: int = MAX_DEPTH) -> None:
        self.preimage = load_network(checkpoint / "preimage")
        self.reach = load_network(checkpoint / "reach")
        self.rng = random.Random(seed)
        self.max_depth = max_depth

    def _preimage(self, state, context, lit) -> set[Literal]:
        data = encode(state, context, [lit])
        return set(decode(data, self.preimage(data).argmax(-1)))

    def _reachable(self, state, lit) -> bool:
        data = encode(state, [lit])
        return bool(self.reach(data).argmax(-1)[Slots(tuple(data.names)).slot(lit)] == 1)

    @torch.no_grad()
    def next_action(self, state: SymbolicSceneGraph, goal: Goal) -> TaskDecision:
        start = time.perf_counter()
        unsatisfied = goal.unsatisfied(state)
        if not unsatisfied:
            return TaskDecision(None, None, time.perf_counter() - start, "the goal holds")
        context = set(unsatisfied)
        # A goal literal waits while its preimage names another unsatisfied goal literal.
        free = [
            lit
            for lit in unsatisfied
            if not (self._preimage(state, context, lit) & context) - {lit}
        ]
        order = list(free or unsatisfied)
        self.rng.shuffle(order)  # the paper's uniform subgoal serialisation
        for lit in order:
            found = self._regress(state, context, lit)
            if found is not None:
                return TaskDecision(action_for(found, state), found, time.perf_counter() - start)
        return TaskDecision(None, None, time.perf_counter() - start, "regression stuck")

    def _regress(self, state, context, lit: Literal) -> Literal | None:
        """Regress one literal until a subgoal one primitive reaches; None if there is none."""
        path = [lit]
        for _ in range(self.max_depth):
            if self._reachable(state, lit) and action_for(lit, state) is not None:
                return lit
            options = [
                m
                for m in sorted(self._preimage(state, context, lit))
                if not state.holds(m) and m not in path
            ]
            if not options:
                return None
            reachable = [m for m in options if self._reachable(state, m)]
            lit = self.rng.choice(reachable or options)
            path.append(lit)
        return None


class ForwardPlanner:
    """The baseline: a network predicts the next subgoal from state and goal directly."""

    name = "forward"

    def __init__(self, checkpoint: Path) -> None:
        self.net = load_network(checkpoint / "forward")

    @torch.no_grad()
    def next_action(self, state: SymbolicSceneGraph, goal: Goal) -> TaskDecision:
        start = time.perf_counter()
        if goal.satisfied_by(state):
            return TaskDecision(None, None, time.perf_counter() - start, "the goal holds")
        data = encode(state, goal.literals)
        probs = self.net(data).softmax(-1)[..., TRUE].masked_fill(~data.valid, 0.0)
        slots = Slots(tuple(data.names))
        for flat in probs.flatten().argsort(descending=True).tolist()[:20]:
            lit = slots.literal(*divmod(flat, probs.shape[1]))
            if not state.holds(lit) and (action := action_for(lit, state)) is not None:
                return TaskDecision(action, lit, time.perf_counter() - start)
        return TaskDecision(None, None, time.perf_counter() - start, "no applicable subgoal")


class FastDownwardTaskPlanner:
    """Fast Downward's plan, first action only: the search-based reference."""

    name = "fd"

    def __init__(self) -> None:
        from hsgplan.planning.fast_downward import FastDownwardPlanner

        self.planner = FastDownwardPlanner()

    def next_action(self, state: SymbolicSceneGraph, goal: Goal) -> TaskDecision:
        from hsgplan.planning.fast_downward import NoPlanError

        start = time.perf_counter()
        try:
            plan = self.planner.plan(state, goal)
        except NoPlanError as e:
            return TaskDecision(None, None, time.perf_counter() - start, str(e))
        action = plan.actions[0] if plan.actions else None
        return TaskDecision(action, None, time.perf_counter() - start)
