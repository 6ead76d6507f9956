"""The regression loop as the paper describes it, for measuring what our loop changes.

At every decision, from the goal: one unsatisfied literal is drawn uniformly (the paper's
subgoal serialisation) and f_reach is asked whether one primitive reaches it; if not, f_preimage
gives its preimage in the regressed context, one of the preimage's unsatisfied literals is
drawn uniformly, and so on, until f_reach says "reachable" (its action is taken) or the depth
cap is met. A path that ends there, or at a literal whose preimage names nothing unsatisfied,
is drawn again from the goal, up to `TRIES` paths a decision ("the whole process is
repeated"); then the decision is "regression stuck" (the paper's overstep).

Unlike `RegressionPlanner` it keeps no chain between decisions, searches one path rather than
breadth first, lets no goal literal wait for another, never takes a literal because its
preimage holds, and has no recovery rule.
"""

from __future__ import annotations

import time
from pathlib import Path

import torch

from hsgplan.domain.actions import Action
from hsgplan.domain.goals import Goal
from hsgplan.domain.recovery import RecoveryRules
from hsgplan.planning.base import TaskDecision
from hsgplan.planning.heuristic import action_for
from hsgplan.planning.regression.planner import (
    MAX_DEPTH,
    Node,
    RegressionPlanner,
    literal_key,
    unsatisfied_literals,
)
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph

# Paths drawn per decision before giving up: the paper gives no number, and ten is not tuned.
# With one path, on tuning seed 900 (the symbolic loop, paper protocol, 30 goals of 2, 3 and 4
# objects), 81 of `checkpoints/task-paper`'s 90 episodes ended stuck, none succeeded.
TRIES = 10


class PaperRegressionPlanner(RegressionPlanner):
    """The paper's loop over the networks of a `hsgplan train task` checkpoint folder."""

    name = "regression-paper"

    def __init__(self, checkpoint: Path, seed: int = 0, max_depth: int = MAX_DEPTH) -> None:
        super().__init__(checkpoint, seed, max_depth, RecoveryRules.none())

    @torch.inference_mode()
    def next_action(
        self, state: SymbolicSceneGraph, goal: Goal, refused: frozenset[Action] = frozenset()
    ) -> TaskDecision:
        start = time.perf_counter()
        if not (unsatisfied := unsatisfied_literals(state, goal)):
            return TaskDecision.none("the goal holds", start)
        for _ in range(TRIES):
            if found := self._descend(state, goal, unsatisfied, refused):
                return TaskDecision.taken(found[1], found[0], start, state.world)
        return TaskDecision.none("regression stuck", start)

    def _descend(self, state, goal: Goal, candidates: list, refused=frozenset()):
        """One path down from the goal: (literal, action) where f_reach says "reachable", or
        None where the path ends first."""
        context = frozenset(goal.literals)
        path = ()
        for _ in range(self.max_depth):
            lit = self.rng.choice(candidates)
            node = Node(lit, context, (*path, lit))
            action = action_for(lit, state)
            if action is not None and action not in refused and self.reachable(state, [lit])[0]:
                return lit, action
            (pre,) = self._preimages(state, [node])
            context = frozenset((context - {lit}) | {m for m in pre if m.positive})
            candidates = sorted(
                (m for m in pre if not state.holds(m) and m not in node.path), key=literal_key
            )
            if not candidates:
                return None
            path = node.path
        return None
