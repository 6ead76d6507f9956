"""An agent whose task level is a learned planner: the next action from the regression
planner (f_preimage, f_reach), its parameters from the geometric sampler as the oracle's.

The learned motion generator replaces the sampler when it arrives; until then this agent
isolates the learned task level, in the simulated world.
"""

from __future__ import annotations

import time
from pathlib import Path

from hsgplan.agents.base import Decision, Feasibility
from hsgplan.agents.geometric_sampler import ParameterChoice
from hsgplan.domain.goals import Goal
from hsgplan.domain.parameters import PrimitiveParams
from hsgplan.domain.transition import Action, Place, Push
from hsgplan.domain.world import SHELVES
from hsgplan.planning.regression.planner import RegressionPlanner
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.sim.outcome import Outcome

TASK_CHECKPOINT = Path("checkpoints/task")


class RegressionAgent:
    """The learned regression planner at the task level, geometric sampling at the motion
    level. The planner is rebuilt at every reset, seeded by the episode's seed."""

    name = "regression"

    def __init__(self, checkpoint: Path = TASK_CHECKPOINT) -> None:
        self.checkpoint = checkpoint
        self.planner = RegressionPlanner(checkpoint)  # a bad checkpoint fails here
        self.params = ParameterChoice()

    def reset(self, goal: Goal, seed: int) -> None:
        self.planner = RegressionPlanner(self.checkpoint, seed=seed)
        self.params.reset()

    def decide(
        self,
        sg: GeometricSceneGraph,
        state: SymbolicSceneGraph,
        goal: Goal,
        feasible: Feasibility | None = None,
    ) -> Decision:
        t0 = time.perf_counter()
        task = self.planner.next_action(state, goal)
        t1 = time.perf_counter()
        if task.action is None:
            return Decision(None, None, t1 - t0, 0.0, task.note)
        params = self.params.choose(sg, task.action, _push_after(task.action), feasible)
        note = "" if params else f"every parameter choice for {task.action} failed"
        return Decision(task.action, params, t1 - t0, time.perf_counter() - t1, note)

    def observe(self, params: PrimitiveParams, outcome: Outcome) -> None:
        self.params.observe(params, outcome)


def _push_after(action: Action) -> Push | None:
    """A place onto a prepush region is there for a push into its shelf: the sampler then
    places the object where the push can start."""
    if isinstance(action, Place):
        return next(
            (Push(action.obj, s) for s in SHELVES if SHELVES[s].prepush == action.target), None
        )
    return None
