"""The search-based baseline, in the spirit of the paper's PDDLStream comparison (Table 2).

Fast Downward plans the whole task symbolically; the plan is then refined: each step's
continuous parameters are sampled (the geometric sampler's candidates, best first) and checked
by running the primitive in a trial of the episode's own world (motion planning, physics and
the symbolic effect the plan expects), depth first, backtracking to another sample of an
earlier step when a step has none that works. When no refinement is found the step that
stopped it is banned and Fast Downward plans again (if that leaves the goal unreachable, the
step before it is banned instead), with twice the samples per step, as PDDLStream's
incremental algorithm widens its sampling. The refined plan is then executed step by step;
when the world departs from it (a primitive fails or the state is not the one expected) the
agent plans again from what it observes.

Times: the task level is Fast Downward's (translation and search); the motion level is the
refinement (sampling, motion planning and simulating every trial).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

from hsgplan.agents.base import Decision
from hsgplan.domain.actions import Action, intended_literal
from hsgplan.domain.goals import Goal
from hsgplan.domain.parameters import PrimitiveParams
from hsgplan.motion.interface import Feasibility
from hsgplan.motion.sampler import candidates
from hsgplan.planning.fast_downward import FastDownwardPlanner, NoPlanError, Plan
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.symbol_mapping import map_symbols
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.sim.lookahead import Lookahead, Trial
from hsgplan.sim.outcome import Outcome


@dataclass(frozen=True)
class SearchConfig:
    """Args:
    samples: parameter samples tried per step of the first plan (doubled for every new plan).
    max_plans: Fast Downward calls per decision before the agent gives up.
    max_trials: primitives simulated per decision, all plans together.
    """

    samples: int = 4
    max_plans: int = 4
    max_trials: int = 150


@dataclass(frozen=True)
class Step:
    action: Action
    params: PrimitiveParams
    before: SymbolicSceneGraph  # the state the plan expects this step to start from


@dataclass(frozen=True)
class Refinement:
    """The parameters found for a plan's first steps; complete when there is one per step.
    `stuck_at` is the deepest step no sample of which worked."""

    params: tuple[PrimitiveParams, ...]
    stuck_at: int
    trials: int


@dataclass
class _Search:
    bans: list[Action] = field(default_factory=list)
    useless: set[Action] = field(default_factory=set)  # bans that left the goal unreachable
    blame: list[Action] = field(default_factory=list)  # the last plan's steps, latest first


class SearchAgent:
    """Args:
    config: the sampling and search budget (`SearchConfig`).
    planner: the symbolic planner (default: Fast Downward as the oracle uses it).
    """

    name = "search"

    def __init__(
        self, config: SearchConfig | None = None, planner: FastDownwardPlanner | None = None
    ) -> None:
        self.config = config or SearchConfig()
        self.planner = planner or FastDownwardPlanner()
        self._queue: list[Step] = []

    def reset(self, goal: Goal, seed: int) -> None:
        self._queue = []

    def observe(self, params: PrimitiveParams, outcome: Outcome) -> None:
        if not outcome.ok:
            self._queue = []

    def decide(
        self,
        sg: GeometricSceneGraph,
        state: SymbolicSceneGraph,
        goal: Goal,
        feasible: Feasibility | None = None,
    ) -> Decision:
        if self._queue and self._queue[0].before == state:
            step = self._queue.pop(0)
            return Decision(step.action, step.params, 0.0, 0.0, "", intended_literal(step.action))
        if not isinstance(feasible, Lookahead):
            return Decision(None, None, 0.0, 0.0, "the search baseline needs the world to try")
        return self._plan(state, goal, feasible)

    def _plan(self, state: SymbolicSceneGraph, goal: Goal, world: Lookahead) -> Decision:
        task = motion = 0.0
        search = _Search()
        samples, trials_left = self.config.samples, self.config.max_trials
        for _ in range(self.config.max_plans):
            start = time.perf_counter()
            try:
                plan = self.planner.plan(state, goal, search.bans)
            except NoPlanError as e:
                task += time.perf_counter() - start
                if not search.bans:
                    return Decision(None, None, task, motion, f"no plan: {e}")
                search.useless.add(search.bans.pop())
                if not self._ban_next(search):
                    break
                continue
            task += time.perf_counter() - start
            if not plan.actions:
                return Decision(None, None, task, motion, "the goal holds")
            start = time.perf_counter()
            with world.trial() as trial:
                found = self._refine(plan, trial, samples, trials_left)
            motion += time.perf_counter() - start
            trials_left -= found.trials
            if len(found.params) == len(plan.actions):
                self._queue = [
                    Step(a, p, s)
                    for a, p, s in zip(plan.actions, found.params, plan.states, strict=False)
                ]
                step = self._queue.pop(0)
                return Decision(
                    step.action, step.params, task, motion, "", intended_literal(step.action)
                )
            if trials_left <= 0:
                break
            search.blame = list(plan.actions[found.stuck_at :: -1])
            if not self._ban_next(search):
                break
            samples *= 2
        return Decision(None, None, task, motion, "no plan could be refined into motions")

    @staticmethod
    def _ban_next(search: _Search) -> bool:
        """Ban the latest step of the last plan not banned or found useless yet."""
        for a in search.blame:
            if a not in search.bans and a not in search.useless:
                search.bans.append(a)
                return True
        return False

    def _refine(self, plan: Plan, trial: Trial, samples: int, budget: int) -> Refinement:
        """Parameters for the plan's steps, depth first over `samples` candidates a step, at
        most `budget` primitives simulated."""
        n = len(plan.actions)
        options = [self._options(trial.scene_graph(), plan, 0, samples)]
        chosen: list[PrimitiveParams] = []
        marks = []
        trials = stuck_at = 0
        while options and len(chosen) < n and trials < budget:
            k = len(chosen)
            if not options[-1]:  # every sample of step k failed: back to step k - 1
                options.pop()
                if marks:
                    trial.back(marks.pop())
                    chosen.pop()
                continue
            params = options[-1].pop(0)
            mark = trial.mark()
            outcome = trial.run(params)
            trials += 1
            sg = trial.scene_graph()
            mapping = map_symbols(sg)
            if outcome.ok and not mapping.anomalies and mapping.state == plan.states[k + 1]:
                marks.append(mark)
                chosen.append(params)
                if k + 1 < n:
                    options.append(self._options(sg, plan, k + 1, samples))
            else:
                trial.back(mark)
                stuck_at = max(stuck_at, k)
        return Refinement(tuple(chosen), stuck_at, trials)

    @staticmethod
    def _options(
        sg: GeometricSceneGraph, plan: Plan, k: int, samples: int
    ) -> list[PrimitiveParams]:
        following = plan.actions[k + 1] if k + 1 < len(plan.actions) else None
        return candidates(sg, plan.actions[k], following)[:samples]
