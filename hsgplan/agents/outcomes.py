"""Checks by outcome: a primitive passes only if, run in the robot's model, it does what it is for.

A dry run asks the motion planner alone: a place onto a tower's top plans, and the object then
slides off the front of the shelf as it settles; a place at a shelf top's front edge plans, and
the box tips onto the prepush region below. An agent made with `try_outcomes`
(`agents/hierarchical.py`) wraps its model's dry run in this check: a primitive that plans is
also run in a trial of the model (taken back at once) and passes only where its intended effect
holds with nothing knocked over, dropped or disturbed (the outcome execution would judge). The
motion generator's proposals go down its ranking through the same check, so a bin that tips
its object is passed over for the next. The model is the robot's: the simulator's poses under
the ground truth, its belief seen through f_p; no domain rule.
"""

from __future__ import annotations

from hsgplan.domain.parameters import PrimitiveParams
from hsgplan.motion.interface import Feasibility


class OutcomeChecks:
    """Args:
    feasible: the model's dry run, with the `trial()` of primitives it opens.

    Outcomes are remembered by the primitive and the model's scene graph they were tried in,
    so that asking again (the agent, then the generator) runs nothing twice.
    """

    def __init__(self, feasible: Feasibility) -> None:
        self._feasible = feasible
        self._seen: dict[tuple, bool] = {}

    def __call__(self, params: PrimitiveParams) -> bool:
        if not self._feasible(params):
            return False
        with self._feasible.trial() as trial:
            key = (params, trial.scene_graph())
            if key not in self._seen:
                self._seen[key] = trial.run(params).ok
            return self._seen[key]

    def trial(self):
        return self._feasible.trial()
