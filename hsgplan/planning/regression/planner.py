"""The learned regression planner, behind the interface of `planning/base.py` (the forward
baseline is `forward.py`).

The regression loop (the paper's phi): f_preimage gives the preimage of one goal literal (the
query) in the context of the goal; a goal literal whose preimage names another unsatisfied goal
literal waits for it (a stack's top for its base). From the free goal literals the planner
regresses breadth first, replacing a literal by the unsatisfied literals of its preimage, until
f_reach says one primitive reaches one (depth cap `MAX_DEPTH`; "regression stuck" when nothing
is found). Among the literals reached at the shallowest level one is drawn uniformly (the
paper's subgoal serialisation): the immediate subgoal g-hat, for which a heuristic
(`action_for`) names the primitive and object.
"""

from __future__ import annotations

import random
import time
from collections import Counter
from dataclasses import dataclass, replace
from functools import lru_cache
from pathlib import Path

import numpy as np
import torch

from hsgplan.domain.actions import Action, Pick
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.goals import Goal
from hsgplan.domain.predicates import Literal
from hsgplan.domain.recovery import ALL_RULES, RecoveryRules
from hsgplan.planning.base import TaskDecision
from hsgplan.planning.heuristic import action_for
from hsgplan.planning.regression.encoding import (
    DONT_CARE,
    Slots,
    encode_computed,
    touching,
)
from hsgplan.planning.regression.gnn import load_network
from hsgplan.planning.regression.lookahead import chain_reachable, imagined, keeps_picks
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph

MAX_DEPTH = 8


@dataclass(frozen=True)
class Loop:
    """What the loop does beyond searching breadth first from the goal (the paper draws one
    path at a time, `paper_loop.py`), each part switchable so that a ladder measures it.

    Attributes:
        waits: a goal literal whose preimage names another unsatisfied goal literal waits
            for it (a stack's top for its base) while the free ones are searched.
        holds: a literal whose whole preimage holds counts as reached, whatever f_reach says.
        keeps_chain: the chain regressed through is followed at the next decision while each
            literal's preimage holds, without asking the networks.
    """

    waits: bool = True
    holds: bool = True
    keeps_chain: bool = True


OUR_LOOP = Loop()


@lru_cache(maxsize=4)
def _inference_networks(checkpoint: str):
    """f_preimage and f_reach of a checkpoint, compiled for inference; loaded once per process
    (a planner is made per episode, and the networks keep no state)."""
    folder = Path(checkpoint)
    return load_network(folder / "preimage").script(), load_network(folder / "reach").script()


def unsatisfied_literals(state: SymbolicSceneGraph, goal: Goal) -> list[Literal]:
    """The goal's literals that do not hold, in order."""
    return [lit for lit in _in_order(goal) if not state.holds(lit)]


@lru_cache(maxsize=64)
def _in_order(goal: Goal) -> list[Literal]:
    """A goal's literals, sorted (once per goal: a decision needs them in order)."""
    return sorted(goal.literals, key=literal_key)


@lru_cache(maxsize=65536)
def literal_key(lit: Literal) -> tuple:
    """The sort key of `Literal`'s own order (predicate, args, sign), without its slow
    generated comparisons; a planner sorts many small sets."""
    return lit.predicate.value, lit.args, lit.positive


@dataclass(frozen=True)
class Node:
    """A literal met while regressing, the subgoal it was regressed within, and its path."""

    lit: Literal
    context: frozenset[Literal]
    path: tuple[Literal, ...]
    # the literals this one was regressed from, with their preimages, root first
    chain: tuple[tuple[Literal, frozenset[Literal]], ...] = ()


class RegressionPlanner:
    """The learned regression planner, from a checkpoint folder made by `hsgplan train task`.

    Regression goes breadth first, one batched network call per question and level: the
    shallowest subgoal one primitive reaches wins (uniformly among equals), so a goal literal
    that is one step away goes before one that needs three. While regressing, the context is
    the regressed subgoal, as in training: the literal is replaced by its preimage.

    After a decision the planner keeps the chain it regressed through (say In(c, shelf_a) <-
    On(c, prepush_a) <- InGrasp(c)). At the next decision, if the next literal up the chain
    has its whole preimage holding in the state now observed, its action is taken without
    asking the networks again; otherwise (a primitive failed, the world moved) the chain is
    dropped and the planner regresses from the goal.

    What it does after a failure is the recovery rule `least_taken`'s
    (`hsgplan.domain.recovery`); with it off it is the paper's planner: the shallowest reachable
    literal, drawn uniformly, or "regression stuck".

    With `look_ahead` (beyond the paper, `lookahead.py`) a subgoal is passed over while another
    is found when f_reach finds a literal up its chain out of reach once those below it are
    imagined achieved (a place onto a full shelf top, before the pick), and, with `sideways`,
    when the pick of an object another goal literal still has to move falls from likely to
    unlikely once the whole chain is imagined achieved (a can put down beside a flat box).
    """

    name = "regression"

    def __init__(
        self,
        checkpoint: Path,
        seed: int = 0,
        max_depth: int = MAX_DEPTH,
        rules: RecoveryRules = ALL_RULES,
        look_ahead: bool = False,
        sideways: bool = True,
        loop: Loop = OUR_LOOP,
    ) -> None:
        self.loop = loop
        self.look_ahead = look_ahead
        self.sideways = sideways
        self.preimage, self.reach = _inference_networks(str(checkpoint))
        self.features = self.preimage.config.features
        if self.reach.config.features != self.features:
            raise InvalidInputError(
                f"'{checkpoint}': f_preimage reads {self.features} and f_reach "
                f"{self.reach.config.features}; both must read the same"
            )
        self.max_depth = max_depth
        self.rules = rules
        self.reset(None, seed)

    def reset(self, goal: Goal | None, seed: int) -> None:
        """A new episode: the seed of the uniform serialisation, nothing remembered."""
        self.rng = random.Random(seed)
        self._taken: dict[tuple[Goal, SymbolicSceneGraph], Counter[Action]] = {}
        self._plan: tuple[Goal, list[tuple[Literal, frozenset[Literal]]], Literal] | None = None
        self._pending: list[str] = []
        self._asked: dict[tuple[SymbolicSceneGraph, Literal], float] = {}

    def _preimages(self, state, nodes: list[Node]) -> list[frozenset[Literal]]:
        # Read out the edges of the query's objects: a preimage names them (the active edges
        # are computed anyway).
        readout = touching(state.nodes, [n.lit.args for n in nodes])
        batch = encode_computed(
            state, [n.context for n in nodes], [n.lit for n in nodes], readout, self.features
        )
        values = self.preimage.computed(*batch.inputs).argmax(-1).numpy()
        rows, preds = np.nonzero((values != DONT_CARE) & batch.valid)
        out: list[set[Literal]] = [set() for _ in nodes]
        slots = Slots.of(state.nodes)
        for i, e, q, v in zip(
            batch.graph[rows].tolist(),
            batch.edge[rows].tolist(),
            preds.tolist(),
            values[rows, preds].tolist(),
            strict=True,
        ):
            out[i].add(slots.valued(e, q, v))
        return [frozenset(x) for x in out]

    def reachable(self, state: SymbolicSceneGraph, lits: list[Literal]) -> list[bool]:
        """f_reach on each literal alone: does the primitive the heuristic names reach it?"""
        return [p > 0.5 for p in self.reach_scores(state, lits)]

    def reach_scores(self, state: SymbolicSceneGraph, lits: list[Literal]) -> list[float]:
        """f_reach's probability of "reachable" for each literal alone."""
        # each literal's slot is on an edge its own goal makes active, so it is computed
        batch = encode_computed(
            state,
            [frozenset((lit,)) for lit in lits],
            [None] * len(lits),
            features=self.features,
        )
        slots = Slots.of(state.nodes)
        e = len(state.nodes) ** 2
        where = [slots.slot(lit) for lit in lits]
        rows = batch.row[[i * e + edge for i, (edge, _) in enumerate(where)]]
        logits = self.reach.computed(*batch.inputs)[rows, [p for _, p in where]]
        return logits.softmax(-1)[:, 1].tolist()

    @torch.inference_mode()
    def next_action(
        self, state: SymbolicSceneGraph, goal: Goal, refused: frozenset[Action] = frozenset()
    ) -> TaskDecision:
        start = time.perf_counter()
        if not (unsatisfied := unsatisfied_literals(state, goal)):
            return TaskDecision.none("the goal holds", start)
        taken = self._taken.setdefault((goal, state), Counter())
        if self.loop.keeps_chain and (step := self._follow(state, goal, refused)) is not None:
            taken[step[1]] += 1
            return TaskDecision.taken(step[1], step[0], start, state.world)
        context = frozenset(goal.literals)
        # objects other goal literals still have to move, whose picks the look-ahead keeps
        self._pending = list(dict.fromkeys(lit.args[0] for lit in unsatisfied if lit.positive))
        self._asked.clear()
        roots = [Node(lit, context, (lit,)) for lit in unsatisfied]
        preimages = self._preimages(state, roots)
        # A goal literal waits while its preimage names another unsatisfied goal literal; if
        # nothing is reached from the free ones (a dependency the network got wrong, or a
        # goal literal stuck behind a full shelf), the waiting ones are tried as well.
        # `least_taken`: an action already taken from this very state (with this goal) failed
        # or came back to it, so of the actions found the least often taken here goes
        # (uniformly among equals). This breaks loops such as picking an object whose shelf is
        # full and putting it back, and a failed action is tried again as often as the detours
        # that only came back here, never the detour for ever: in the world a primitive may
        # pass on another try. A loop that never passes ends at the step limit, the paper's
        # overstep.
        pairs = list(zip(roots, preimages, strict=True))
        free = [(n, p) for n, p in pairs if not p & set(unsatisfied) - {n.lit}]
        counts = taken if self.rules.least_taken else None
        vetoed: list[Node] = []
        frontiers = (free, [x for x in pairs if x not in free]) if self.loop.waits else (pairs,)
        for frontier in frontiers:
            found = self._search(state, frontier, set(refused), counts, vetoed)
            if found is not None:
                return self._take(state, goal, *found, taken, start)
        # every subgoal found serves a literal out of reach once it is achieved: the first
        # ones found, as the planner takes them without looking ahead
        if (found := self._choose(state, vetoed, set(refused), counts)) is not None:
            return self._take(state, goal, *found, taken, start)
        return TaskDecision.none("regression stuck", start)

    def _take(self, state, goal, node: Node, action: Action, taken, start) -> TaskDecision:
        taken[action] += 1
        self._plan = (goal, list(reversed(node.chain)), node.path[0])
        decision = TaskDecision.taken(action, node.lit, start, state.world)
        if isinstance(action, Pick) and node.chain:
            # what the pick is for: the action of the literal next up the chain, in the state
            # with the object in hand (an agent that checks its actions tries both)
            after = imagined(state, node.lit)
            up = action_for(node.chain[-1][0], after) if after is not None else None
            decision = replace(decision, following=up)
        return decision

    def _follow(self, state, goal, avoid) -> tuple[Literal, Action, Literal] | None:
        """The next step up the kept chain, if its preimage holds now, and the chain's root."""
        if self._plan is None or self._plan[0] != goal:
            return None
        chain = self._plan[1]
        while chain and state.holds(chain[0][0]):
            chain.pop(0)
        if chain and all(state.holds(m) for m in chain[0][1]):
            action = action_for(chain[0][0], state)
            if action is not None and action not in avoid:
                return chain[0][0], action, self._plan[2]
        self._plan = None
        return None

    def _ahead(self, state, nodes: list[Node], vetoed: list[Node]) -> list[Node]:
        """The nodes whose chain stays reachable (all of them without the look-ahead); the
        first nodes passed over are kept in `vetoed`."""
        if not self.look_ahead:
            return nodes
        kept = []
        for n in nodes:
            up = [lit for lit, _ in reversed(n.chain)]
            if not chain_reachable(state, n.lit, up, self._reach_once):
                continue
            if self.sideways and not keeps_picks(
                state, [n.lit, *up], self._pending, self._reach_once
            ):
                continue
            kept.append(n)
        if not vetoed:
            vetoed.extend(n for n in nodes if n not in kept)
        return kept

    def _reach_once(self, state: SymbolicSceneGraph, lits: list[Literal]) -> list[float]:
        """`reach_scores`, each (state, literal) asked once per decision: the look-ahead asks
        every candidate's chain about the same current and imagined states (f_reach reads each
        literal alone, so an answer does not depend on what it is asked with)."""
        asked = self._asked
        new = [lit for lit in dict.fromkeys(lits) if (state, lit) not in asked]
        if new:
            scores = self.reach_scores(state, new)
            asked.update(((state, lit), p) for lit, p in zip(new, scores, strict=True))
        return [asked[state, lit] for lit in lits]

    def _search(self, state, frontier, avoid, counts, vetoed):
        """Breadth first from the frontier: a (node, action) one primitive reaches, or None.

        A node is reached when f_reach says so, or when its whole preimage already holds
        (then, by what a preimage means, one primitive achieves it). Where a level's
        preimages are known, f_reach is asked about it and the next level in one call."""
        reach: dict[Literal, float] = {}
        for _ in range(self.max_depth):
            if not frontier:
                return None
            known = all(pre is not None for _, pre in frontier)
            children = self._children(state, frontier) if known else []
            ask = [n.lit for n, _ in frontier + children if n.lit not in reach]
            ask = list(dict.fromkeys(ask))
            if ask:
                reach.update(zip(ask, self.reach_scores(state, ask), strict=True))
            hits = self._ahead(state, [n for n, _ in frontier if reach[n.lit] > 0.5], vetoed)
            if found := self._choose(state, hits, avoid, counts):
                return found
            frontier = self._with_preimages(state, frontier)
            holding = frontier if self.loop.holds else []
            done = [n for n, pre in holding if all(state.holds(m) for m in pre)]
            done = self._ahead(state, done, vetoed)
            if found := self._choose(state, done, avoid, counts):
                return found
            frontier = children if known else self._children(state, frontier)
        return None

    def _choose(self, state, nodes: list[Node], avoid, counts: Counter[Action] | None = None):
        """One of the nodes' actions not in `avoid`: with `counts` (how often each was taken
        here), one of the least taken."""
        hits = [
            (n, a) for n in nodes if (a := action_for(n.lit, state)) is not None and a not in avoid
        ]
        if counts is not None and hits:
            least = min(counts[a] for _, a in hits)
            hits = [h for h in hits if counts[h[1]] == least]
        return self.rng.choice(hits) if hits else None  # the paper's uniform serialisation

    def _with_preimages(self, state, frontier):
        missing = [n for n, pre in frontier if pre is None]
        found = dict(zip(missing, self._preimages(state, missing), strict=True)) if missing else {}
        return [(n, found[n] if pre is None else pre) for n, pre in frontier]

    @staticmethod
    def _children(state, frontier):
        """The next level: each node's unsatisfied preimage literals, in the node's regressed
        context (the node's literal replaced by its preimage)."""
        seen, out = set(), []
        for node, pre in frontier:
            context = frozenset((node.context - {node.lit}) | {m for m in pre if m.positive})
            for m in sorted(pre, key=literal_key):
                if state.holds(m) or m in node.path or m in seen:
                    continue
                seen.add(m)
                chain = node.chain + ((node.lit, pre),)
                out.append((Node(m, context, node.path + (m,), chain), None))
        return out
