"""The oracle: Fast Downward's next action, parameters from geometry, closed loop.

After every primitive it compares the observed symbolic state with the state its plan
predicted: when they agree it goes on with the rest of the plan (a suffix of a shortest plan is
a shortest plan from there, so Fast Downward would answer the same), and when they differ it
plans again from what it sees. It measures the world (what a planner that knows the rules can
achieve in it) and is the ceiling the learned agents are compared against.
"""

from __future__ import annotations

import time

from hsgplan.agents.base import Decision, Feasibility
from hsgplan.agents.geometric_sampler import ParameterChoice
from hsgplan.domain.goals import Goal
from hsgplan.domain.parameters import PrimitiveParams
from hsgplan.planning.fast_downward import FastDownwardPlanner, NoPlanError, Plan
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.sim.outcome import Outcome


class OracleAgent:
    name = "oracle"

    def __init__(self, planner: FastDownwardPlanner | None = None) -> None:
        self.planner = planner or FastDownwardPlanner()
        self.params = ParameterChoice()
        self.plan: Plan | None = None

    def reset(self, goal: Goal, seed: int) -> None:
        self.params.reset()
        self.plan = None

    def decide(
        self,
        sg: GeometricSceneGraph,
        state: SymbolicSceneGraph,
        goal: Goal,
        feasible: Feasibility | None = None,
    ) -> Decision:
        t0 = time.perf_counter()
        plan = self._remaining(state)
        if plan is None:
            try:
                plan = self.plan = self.planner.plan(state, goal)
            except NoPlanError as e:
                return Decision(None, None, time.perf_counter() - t0, 0.0, f"no plan: {e}")
        t1 = time.perf_counter()
        if not plan.actions:
            return Decision(None, None, t1 - t0, 0.0, "the goal holds")
        following = plan.actions[1] if len(plan.actions) > 1 else None
        params = self.params.choose(sg, plan.actions[0], following, feasible)
        note = "" if params else f"every parameter choice for {plan.actions[0]} failed"
        return Decision(plan.actions[0], params, t1 - t0, time.perf_counter() - t1, note)

    def _remaining(self, state: SymbolicSceneGraph) -> Plan | None:
        """The rest of the current plan, if the state is one the plan passes through."""
        if self.plan is None or state not in self.plan.states[:-1]:
            return None
        i = self.plan.states.index(state)
        return Plan(self.plan.actions[i:], self.plan.states[i:], 0.0, self.plan.planner)

    def observe(self, params: PrimitiveParams, outcome: Outcome) -> None:
        self.params.observe(params, outcome)
