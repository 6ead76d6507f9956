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

It also looks sideways: a chain is passed over when, with all of it imagined achieved, the
pick of an object another goal literal still has to move falls from likely to unlikely by
f_reach. Put a can beside a flat box on a shelf top and the box may no longer be picked (the
hand is wider than the box along its closing axis); f_reach learned that from the world, and
the box is moved first while it still can be. The same holds for a base stacked onto before it
has moved.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from hsgplan.domain.predicates import Literal, Predicate, in_grasp
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph

# f_reach's chance at or below which a literal up the chain counts as out of reach. Lower than
# the planner's 0.5: f_reach learned the world's odds, in which a top's last free spot is a
# coin toss and a full one near zero. Chosen on tuning seed 900 (docs/decisions.md).
AHEAD_REACH = 0.1
# The planner's own line between likely and unlikely, for the pick of an object still to move.
PICK_REACH = 0.5
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


def keeps_picks(
    state: SymbolicSceneGraph,
    chain: Sequence[Literal],
    pending: Sequence[str],
    reach: Callable[[SymbolicSceneGraph, list[Literal]], list[float]],
) -> bool:
    """Whether every object of `pending` (objects other goal literals still have to move) that
    f_reach finds likely to be picked now stays so once `chain` (the subgoal first, its root
    last) is imagined achieved literal by literal. The objects the chain moves are left out; a
    base it stacks onto is not (stacked on before it moves, it is trapped as well)."""
    others = [o for o in pending if all(o != lit.args[0] for lit in chain)]
    if not others:
        return True
    after = state
    for lit in chain:
        after = imagined(after, lit)
        if after is None:
            return True
    picks = [in_grasp(o) for o in others]
    before = reach(state, picks)
    now = reach(after, picks)
    return not any(b > PICK_REACH >= a for b, a in zip(before, now, strict=True))
