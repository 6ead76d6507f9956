"""The regression planner's look one step up its chain (beyond the paper, `regression-ahead`).

Regressing `On(x, shelf_a)` gives `InGrasp(x)`, which one pick reaches, so the paper's planner
picks x up. Nothing in a preimage says that the shelf top has room: capacity is a count, which
no literal names, so the demonstrations cannot teach f_preimage to ask for it. f_reach learned
it from the world (it gives a full top's place a low chance), but the planner asks it only
about the subgoal it is about to take, never about the literal that subgoal serves. With
eight or more objects shelf tops fill, and the held object's place then fails.

The look-ahead asks f_reach one question more: in the state with the subgoal imagined
achieved, is the literal it was regressed from reachable? A subgoal whose answer is no is
passed over while another is found. Imagining a subgoal achieved moves its object to where
the literal says and nothing else (`SymbolicSceneGraph.moved`); it reads no precondition, and
a literal that places no object (Clear, a negation) is not imagined.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from hsgplan.domain.predicates import Literal, Predicate
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph

# f_reach's chance at or below which a literal up the chain counts as out of reach. Lower than
# the planner's 0.5: f_reach learned the world's odds, in which a top's last free spot is a
# coin toss and a full one near zero. Chosen on tuning seed 900 (docs/decisions.md).
AHEAD_REACH = 0.1
PLACEMENTS = (Predicate.ON, Predicate.IN, Predicate.IN_GRASP)


def imagined(state: SymbolicSceneGraph, lit: Literal) -> SymbolicSceneGraph | None:
    """The state with `lit` achieved, or None for a literal that places no object."""
    if not lit.positive or lit.predicate not in PLACEMENTS:
        return None
    return state.moved(lit)


def chain_reachable(
    state: SymbolicSceneGraph,
    lit: Literal,
    up: Sequence[Literal],
    reach: Callable[[SymbolicSceneGraph, list[Literal]], list[float]],
) -> bool:
    """Whether each literal of `up` (the chain above `lit`, nearest first) stays reachable, by
    `reach` (f_reach's chances) above AHEAD_REACH, once the ones below it are imagined
    achieved in turn; a literal that places nothing ends the look there."""
    below = lit
    for above in up:
        state = imagined(state, below)
        if state is None:
            return True
        if reach(state, [above])[0] <= AHEAD_REACH:
            return False
        below = above
    return True
