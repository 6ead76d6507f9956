"""What every motion generator offers an agent, and the failure memory they share: no network
here, so that an agent of the geometric sampler (the oracle) never loads torch.

The memory is the recovery rule `failed_bins` (`hsgplan.domain.recovery`), told in
`motion/generator.py`'s docstring.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

from hsgplan.domain.actions import Action
from hsgplan.domain.parameters import MotionPrimitive, PrimitiveParams
from hsgplan.domain.predicates import Literal, Predicate
from hsgplan.domain.recovery import ALL_RULES, RecoveryRules
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.sim.outcome import Outcome, Status

Feasibility = Callable[[PrimitiveParams], bool]
# Failures that say these parameters will not work here; anything else may be tried again.
DO_NOT_RETRY = frozenset({Status.NO_IK, Status.NO_PATH, Status.EFFECT_NOT_REACHED, Status.INVALID})
# Candidates a generator that checks its proposals dry-runs per decision (best first) before it
# proposes its first choice regardless: the geometric sampler, and the learned generators'
# `-checked` variants, with the same budget.
DRY_RUNS = 30
# Failed pushes of an object since it was put down, after which a bin generator gives up on the
# spot (see `_BinGenerator`).
PUSH_TRIES = 3


def primitive_of(subgoal: Literal) -> MotionPrimitive:
    return MotionPrimitive.PLACE if subgoal.predicate is Predicate.ON else MotionPrimitive.PUSH


class MotionGenerator(Protocol):
    name: str

    def reset(self, seed: int) -> None:
        """A new episode: nothing has failed yet."""

    def propose(
        self,
        sg: GeometricSceneGraph,
        action: Action,
        following: Action | None = None,
        feasible: Feasibility | None = None,
    ) -> PrimitiveParams | None:
        """Parameters for `action` in the scene `sg` (None when a generator has none to offer).

        `following` is the action the task planner expects next, where it knows one;
        `feasible`, when given, dry-runs a candidate (plans it without executing it)."""

    def observe(self, params: PrimitiveParams, outcome: Outcome) -> None:
        """What executing the proposal came to."""


def scene_key(sg: GeometricSceneGraph) -> tuple:
    """The scene as the failure memory compares scenes: what is held, and every other object's
    pose to the cm. The held object's pose is the grasp's, different after every pick; where it
    may go depends on the rest of the scene."""
    return sg.held, tuple(
        (n.name, *(round(v * 100) for v in n.pose.position)) for n in sg.nodes if n.name != sg.held
    )


class SingleShotMemory:
    """What every generator remembers within an episode: the parameters that failed for good,
    by the scene they failed in (nothing, with the `failed_bins` rule off).

    Args:
        rules: the recovery rules in force (`hsgplan.domain.recovery`).
    """

    def __init__(self, rules: RecoveryRules = ALL_RULES) -> None:
        self.rules = rules
        self.failed: dict[tuple, set[PrimitiveParams]] = {}
        self._scene: tuple | None = None

    def reset(self, seed: int) -> None:
        self.failed = {}
        self._scene = None

    def untried(self, sg: GeometricSceneGraph, options: list) -> list:
        """The options that have not failed in this very scene (the one proposed in next)."""
        self._scene = scene_key(sg)
        failed = self.failed.get(self._scene, set())
        return [o for o in options if o not in failed]

    def observe(self, params: PrimitiveParams, outcome: Outcome) -> None:
        if self.rules.failed_bins and outcome.status in DO_NOT_RETRY and self._scene is not None:
            self.failed.setdefault(self._scene, set()).add(params)
