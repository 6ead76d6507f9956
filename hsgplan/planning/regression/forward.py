"""The forward baseline: a network predicts the next subgoal from state and goal directly (the
paper's comparison for the regression planner), behind the interface of `planning/base.py`."""

from __future__ import annotations

import time
from collections import Counter
from pathlib import Path

import torch

from hsgplan.domain.actions import Action
from hsgplan.domain.goals import Goal
from hsgplan.planning.base import TaskDecision
from hsgplan.planning.heuristic import action_for
from hsgplan.planning.regression.encoding import TRUE, Slots, encode
from hsgplan.planning.regression.gnn import load_network
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph

# A primitive can fail for motion reasons in the simulated world and succeed when tried again;
# an action that failed this often from the very same state is taken there again only when
# nothing else is found.
GIVE_UP_AFTER = 2


def _given_up(failures: Counter[Action] | None) -> set[Action]:
    return {a for a, n in (failures or {}).items() if n >= GIVE_UP_AFTER}


class ForwardPlanner:
    """The baseline: a network predicts the next subgoal from state and goal directly.

    It runs under the regression planner's loop-breaking: the heuristic names the action (no
    preconditions checked), and an action already taken from this very state with this goal
    (it failed, or came back here) is avoided while another of the network's top subgoals
    names a different one, and one that failed here (the state stayed) `GIVE_UP_AFTER` times is
    not taken here while another is found (the likeliest is tried again when none is)."""

    name = "forward"
    TOP = 20  # subgoals considered per decision, most probable first

    def __init__(self, checkpoint: Path) -> None:
        self.net = load_network(checkpoint / "forward")
        self.reset(None, 0)

    def reset(self, goal: Goal | None, seed: int) -> None:
        """A new episode: nothing remembered."""
        self._taken: dict[tuple[Goal, SymbolicSceneGraph], set[Action]] = {}
        self._last: tuple[SymbolicSceneGraph, Action] | None = None
        self._failed: dict[SymbolicSceneGraph, Counter[Action]] = {}

    @torch.inference_mode()
    def next_action(
        self, state: SymbolicSceneGraph, goal: Goal, refused: frozenset[Action] = frozenset()
    ) -> TaskDecision:
        start = time.perf_counter()
        if goal.satisfied_by(state):
            return TaskDecision.none("the goal holds", start)
        data = encode(state, goal.literals, features=self.net.config.features)
        probs = self.net(data).softmax(-1)[..., TRUE].masked_fill(~data.valid, 0.0)
        slots = Slots(tuple(data.names))
        ranked = []
        for flat in probs.flatten().argsort(descending=True).tolist()[: self.TOP]:
            lit = slots.literal(*divmod(flat, probs.shape[1]))
            action = None if state.holds(lit) else action_for(lit, state)
            if action is not None and action not in refused:
                ranked.append((lit, action))
        if self._last is not None and self._last[0] == state:
            self._failed.setdefault(state, Counter())[self._last[1]] += 1
        failed_here = _given_up(self._failed.get(state))
        taken = self._taken.setdefault((goal, state), set())
        fresh = [(lit, a) for lit, a in ranked if a not in taken]
        fresh = fresh or [(lit, a) for lit, a in ranked if a not in failed_here] or ranked
        if not fresh:
            return TaskDecision.none("no subgoal", start)
        lit, action = fresh[0]
        taken.add(action)
        self._last = (state, action)
        return TaskDecision.taken(action, lit, start, state.world)
