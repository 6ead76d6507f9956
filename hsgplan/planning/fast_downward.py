"""Fast Downward through unified-planning: the paper's algorithmic (search-based) planner.

It writes demonstrations for the learned planner and is the search baseline that the learned
planner is timed against.
"""

from __future__ import annotations

import contextlib
import importlib.resources
import math
import os
import signal
import subprocess
import sys
import tempfile
import time
from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import unified_planning as up
from unified_planning.engines import PlanGenerationResultStatus as Status
from unified_planning.shortcuts import OneshotPlanner

from hsgplan.domain.actions import Action, intended_literal
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.goals import Goal
from hsgplan.planning.base import TaskDecision
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.symbolic.pddl import build_problem, decode
from hsgplan.symbolic.transition import apply

up.shortcuts.get_environment().credits_stream = None


class NoPlanError(InvalidInputError):
    """The planner proved the goal unreachable from the state, or gave up within its time."""


@dataclass(frozen=True)
class Plan:
    """A sequence of actions and the symbolic state after each (`states[0]` is the start).

    `seconds` is the planner's wall time, translation and search included.
    """

    actions: tuple[Action, ...]
    states: tuple[SymbolicSceneGraph, ...]
    seconds: float
    planner: str

    def __len__(self) -> int:
        return len(self.actions)


# Weighted A* (w=2) over the FF heuristic with preferred operators: as fast as LAMA's first
# solution here but with plans close to optimal (LAMA's were up to 40% longer on 6 objects),
# while A* with LM-cut gives shortest plans but stops scaling past 8 objects.
SATISFICING_SEARCH = "let(hff,ff(),lazy_wastar([hff],preferred=[hff],w=2))"


# Up to this many objects A* with LM-cut answers within about half a second (measured by
# `hsgplan bench symbolic`), so `optimal=None` buys shortest plans there at little cost.
AUTO_OPTIMAL_MAX_OBJECTS = 6


class FastDownwardPlanner:
    """Plans with Fast Downward.

    Args:
        optimal: True for shortest plans (A* with LM-cut); False for weighted A* with FF,
            which scales to 12 objects but may take detours; None (default) for the former
            up to `AUTO_OPTIMAL_MAX_OBJECTS` objects in the scene and the latter beyond.
        timeout_s: wall time after which planning gives up with `NoPlanError`.
    """

    def __init__(self, optimal: bool | None = None, timeout_s: float = 60.0) -> None:
        self.optimal = optimal
        self.timeout_s = timeout_s
        self.name = {None: "fd-auto", True: "fd-optimal", False: "fd-wastar"}[optimal]

    def _optimal_for(self, state: SymbolicSceneGraph) -> bool:
        if self.optimal is None:
            return len(state.objects) <= AUTO_OPTIMAL_MAX_OBJECTS
        return self.optimal

    def _engine(self, optimal: bool):
        if optimal:
            return OneshotPlanner(name="fast-downward-opt")
        return OneshotPlanner(
            name="fast-downward", params={"fast_downward_search_config": SATISFICING_SEARCH}
        )

    def plan(self, state: SymbolicSceneGraph, goal: Goal, banned: Iterable[Action] = ()) -> Plan:
        """Plan from the state to the goal, using none of the `banned` ground actions; every
        step is replayed in the transition model."""
        start = time.perf_counter()
        missing = [o for o in goal.objects if o not in state.objects]
        if missing:
            raise InvalidInputError(f"the goal names '{missing[0]}', which is not in the scene")
        if goal.satisfied_by(state):
            return Plan((), (state,), time.perf_counter() - start, self.name)
        problem = build_problem(state, goal, banned).problem
        optimal = self._optimal_for(state)
        # Fast Downward's driver writes `output.sas` into the working directory: planners
        # running side by side (test workers, data-collection pools) must not share one.
        with (
            tempfile.TemporaryDirectory(prefix="hsgplan-fd-") as tmp,
            contextlib.chdir(tmp),
            self._engine(optimal) as engine,
        ):
            result = engine.solve(problem, timeout=self.timeout_s)
        seconds = time.perf_counter() - start
        if result.status not in (Status.SOLVED_SATISFICING, Status.SOLVED_OPTIMALLY):
            reason = {
                Status.UNSOLVABLE_PROVEN: "no sequence of pick, place and push reaches it",
                Status.TIMEOUT: f"no plan found within {self.timeout_s:.0f} s",
            }.get(result.status, f"the planner stopped with {result.status.name}")
            raise NoPlanError(f"goal '{goal}' from '{state}': {reason}")
        actions = tuple(
            decode(a.action.name, [str(p) for p in a.actual_parameters])
            for a in result.plan.actions
        )
        states = [state]
        for a in actions:
            states.append(apply(states[-1], a))
        return Plan(actions, tuple(states), seconds, "fd-optimal" if optimal else "fd-wastar")


@dataclass(frozen=True)
class PddlPlan:
    """A plan Fast Downward found for PDDL text: each step's action name and arguments (lower
    case, as Fast Downward writes them); `seconds` is the driver's wall time (translation and
    search, the process start included)."""

    steps: tuple[tuple[str, tuple[str, ...]], ...]
    seconds: float


# The driver's exit codes for "no plan exists" (the translator or the search proved it), "none
# found" (an incomplete search gave up) and "out of time or memory": each means
# the caller should try something else; 232 is a component the time limit stopped by SIGXCPU
# (256 - 24), which the driver reports as it is.
_NO_PLAN_CODES = (10, 11, 12, 20, 21, 22, 23, 24, 232)
# Seconds the driver gets past its own time limit before its process group is killed.
_KILL_GRACE_S = 5.0


def solve_pddl(
    domain: str, problem: str, search: str = SATISFICING_SEARCH, timeout_s: float = 60.0
) -> PddlPlan:
    """Fast Downward's driver on PDDL text (what unified-planning cannot express, such as
    derived predicates), in a temporary folder of its own; `NoPlanError` when it finds none
    within `timeout_s` (the driver's limit, on its processor time)."""
    driver = importlib.resources.files("up_fast_downward") / "downward" / "fast-downward.py"
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="hsgplan-fd-") as tmp:
        folder = Path(tmp)
        (folder / "domain.pddl").write_text(domain)
        (folder / "problem.pddl").write_text(problem)
        cmd = [sys.executable, str(driver), "--plan-file", "plan"]
        # a limit of 1 s stops the translator before it starts (measured: exit 232 in 0.04 s)
        cmd += ["--overall-time-limit", f"{max(2, math.ceil(timeout_s))}s"]
        cmd += ["domain.pddl", "problem.pddl", "--search", search]
        code, tail = _run_group(cmd, folder, timeout_s + _KILL_GRACE_S)
        plan_file = folder / "plan"
        if code in _NO_PLAN_CODES or code is None or (code == 0 and not plan_file.exists()):
            raise NoPlanError(f"Fast Downward found no plan (exit code {code})")
        if code != 0:
            raise RuntimeError(f"Fast Downward failed ({code}): {tail}")
        lines = plan_file.read_text().splitlines()
    steps = []
    for line in lines:
        if line.startswith("("):
            name, *args = line.strip("() ").split()
            steps.append((name, tuple(args)))
    return PddlPlan(tuple(steps), time.perf_counter() - start)


def _run_group(cmd: list[str], cwd: Path, timeout_s: float) -> tuple[int | None, str]:
    """Run a command in a process group of its own: the driver starts the translator and the
    search as children, which killing the driver alone would leave running. The exit code
    (None when it had to be killed) and the last lines it wrote."""
    proc = subprocess.Popen(
        cmd,
        cwd=cwd,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,
    )
    try:
        out, _ = proc.communicate(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        return None, ""
    return proc.returncode, " | ".join((out or "").strip().splitlines()[-3:])


# Times the oracle names one action from one state before it gives it up there: a budget, as
# the motion generator's retries are, not tuned.
TAKEN_LIMIT = 3


class FastDownwardTaskPlanner:
    """Fast Downward behind the task-planner interface: the next action of its plan, serving
    the literal that action makes true.

    With `follow_plan` (the default) it compares the observed state with the state its plan
    predicted and goes on with the rest of the plan while they agree (a suffix of a shortest
    plan is a shortest plan from there, so Fast Downward would answer the same), planning
    again only when the world departs from it; without, it plans from every state.

    It remembers the actions it named from each state of the episode. Back in a state it named
    an action from (the action failed and left the state as it was, or a later one led back),
    it plans without the actions named there while such a plan exists, and names none more than
    `TAKEN_LIMIT` times from the same state: a place whose every pose the arm refuses is given
    up there for another plan, or the planner stops, rather than being tried to the step
    limit. An action `refused` by the agent is planned around in the same way.
    """

    name = "fd"

    def __init__(self, follow_plan: bool = True, planner: FastDownwardPlanner | None = None):
        self.planner = planner or FastDownwardPlanner()
        self.follow_plan = follow_plan
        self.plan: Plan | None = None
        # the actions named from each state this episode, and how often
        self.taken: dict[SymbolicSceneGraph, Counter[Action]] = {}

    def reset(self, goal: Goal | None, seed: int) -> None:
        self.plan = None
        self.taken = {}

    def next_action(
        self, state: SymbolicSceneGraph, goal: Goal, refused: frozenset[Action] = frozenset()
    ) -> TaskDecision:
        start = time.perf_counter()
        taken = self.taken.setdefault(state, Counter())
        plan = self._remaining(state) if self.follow_plan else None
        if plan is None or (plan.actions and (plan.actions[0] in refused or taken)):
            try:
                plan = self.plan = self._plan_around(state, goal, refused, taken)
            except NoPlanError as e:
                return TaskDecision.none(f"no plan: {e}", start)
        if not plan.actions:
            return TaskDecision.none("the goal holds", start)
        action = plan.actions[0]
        taken[action] += 1
        following = plan.actions[1] if len(plan.actions) > 1 else None
        seconds = time.perf_counter() - start
        return TaskDecision(action, intended_literal(action), seconds, following=following)

    def _plan_around(
        self,
        state: SymbolicSceneGraph,
        goal: Goal,
        refused: frozenset[Action],
        taken: Counter[Action],
    ) -> Plan:
        """A plan without the refused actions and those named here before, else one without
        the refused actions and those given up here (named `TAKEN_LIMIT` times)."""
        given_up = {a for a, n in taken.items() if n >= TAKEN_LIMIT}
        options = [set(refused) | set(taken)] if taken else []
        options.append(set(refused) | given_up)
        for i, banned in enumerate(options):
            try:
                return self.planner.plan(state, goal, banned=frozenset(banned))
            except NoPlanError:
                if i == len(options) - 1:
                    raise
        raise AssertionError("unreachable: the last option returns or raises")

    def _remaining(self, state: SymbolicSceneGraph) -> Plan | None:
        """The rest of the current plan, if the state is one the plan passes through."""
        if self.plan is None or state not in self.plan.states[:-1]:
            return None
        i = self.plan.states.index(state)
        return Plan(self.plan.actions[i:], self.plan.states[i:], 0.0, self.plan.planner)
