"""The interface every agent offers the closed loop."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

from hsgplan.domain.actions import Action
from hsgplan.domain.goals import Goal
from hsgplan.domain.parameters import PrimitiveParams
from hsgplan.domain.predicates import Literal
from hsgplan.motion.interface import Feasibility
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.sim.outcome import Outcome


@dataclass(frozen=True)
class Decision:
    """The next primitive, or None with a reason when the agent has nothing to offer.

    `subgoal` is the literal the action serves (the task level's ĝ); `task_seconds` is spent
    choosing the symbolic action (the task level), `motion_seconds` choosing its parameters
    (the motion level, before execution).
    """

    action: Action | None
    params: PrimitiveParams | None
    task_seconds: float
    motion_seconds: float
    note: str = ""
    subgoal: Literal | None = None


class Agent(Protocol):
    name: str

    def reset(self, goal: Goal, seed: int) -> None:
        """A new episode towards `goal`."""

    def decide(
        self,
        sg: GeometricSceneGraph,
        state: SymbolicSceneGraph,
        goal: Goal,
        feasible: Feasibility | None = None,
    ) -> Decision:
        """The next primitive from the observation (s_g) and its symbolic reading (s_s).

        `feasible`, when given, plans a candidate without executing it (a dry run); agents
        that choose in a single shot, as the paper's do, leave it unused.
        """

    def observe(self, params: PrimitiveParams, outcome: Outcome) -> None:
        """What executing the last decision came to."""
