"""The one agent class: a task planner and a motion generator, composed as the paper composes
them. The task planner reads the symbolic scene graph s_s and names the next action and the
subgoal it serves; the motion generator reads the geometric scene graph s_g and chooses the
action's parameters.

Beyond the paper, an agent made with `check_actions` tries the task planner's action in its
model of the scene before it takes it (the dry runs a checked motion generator makes: the
motion planner, no domain rule): the primitive must plan and, for a pick the planner means to
follow with a place or a stack, that place must plan once the pick is done (tried in the model
and taken back). An action that fails the check is refused: the task planner is asked again
without it, up to `REFUSALS` times, after which its first choice is taken as without checks.
With `clear_way` as well, before it takes that doomed choice it looks for a neighbour to move
aside first (`agents/clearing.py`). Under the recovery rule `refuse_repeats` it also refuses an
action that succeeded from the very state it observes now: the world came back here after it;
under `stuck_goal_literals`, when the task planner finds nothing, it offers the checks the
actions of the goal's unsatisfied literals (`agents/stuck.py`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace

from hsgplan.agents.base import Decision
from hsgplan.agents.clearing import CLEARINGS, find_clearing, follows
from hsgplan.agents.stuck import goal_actions
from hsgplan.domain.actions import Action, Pick, Place, Push
from hsgplan.domain.goals import Goal
from hsgplan.domain.parameters import PrimitiveParams
from hsgplan.domain.predicates import in_grasp, on
from hsgplan.domain.recovery import ALL_RULES, RecoveryRules
from hsgplan.motion.interface import Feasibility, MotionGenerator
from hsgplan.planning.base import TaskPlanner
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.sim.outcome import Outcome

# Actions refused per decision before the task planner's first choice is taken regardless: a
# budget, as the dry runs per proposal are, not tuned.
REFUSALS = 4


@dataclass(frozen=True)
class _Choice:
    """A decision, the action the task planner named for it (a push given up becomes a pick)
    and the action the planner means to take after it."""

    decision: Decision
    named: Action | None
    following: Action | None


class HierarchicalAgent:
    """Args:
    name: what episodes record as the agent.
    planner: the task level (`hsgplan.planning.base.TaskPlanner`).
    motion: the motion level (`hsgplan.motion.interface.MotionGenerator`).
    rules: the recovery rules in force (`hsgplan.domain.recovery`); this class applies the
        task half of `push_give_up` (a push with no parameters becomes a pick).
    check_actions: try each action in the model of the scene before taking it, and refuse
        those that fail (see the module's docstring).
    clear_way: with `check_actions`, when every action offered failed its check, move a
        neighbour that stands in the way aside first (`agents/clearing.py`).
    """

    def __init__(
        self,
        name: str,
        planner: TaskPlanner,
        motion: MotionGenerator,
        rules: RecoveryRules = ALL_RULES,
        check_actions: bool = False,
        clear_way: bool = False,
    ) -> None:
        self.name = name
        self.planner = planner
        self.motion = motion
        self.rules = rules
        self.check_actions = check_actions
        self.clear_way = clear_way
        # what clearing the way still has to do: neighbours' picks and places, then the action
        self._queued: list[tuple[Action, Action | None]] = []
        self._clearings = 0
        # `refuse_repeats`: the actions that succeeded from each state (with each goal), and
        # the decision being executed, recorded once its outcome is known
        self._succeeded: dict[tuple[Goal, SymbolicSceneGraph], set[Action]] = {}
        self._deciding: tuple[Goal, SymbolicSceneGraph, Action] | None = None

    def reset(self, goal: Goal, seed: int) -> None:
        self.planner.reset(goal, seed)
        self.motion.reset(seed)
        self._queued, self._clearings = [], 0
        self._succeeded, self._deciding = {}, None

    def decide(
        self,
        sg: GeometricSceneGraph,
        state: SymbolicSceneGraph,
        goal: Goal,
        feasible: Feasibility | None = None,
    ) -> Decision:
        if not self.check_actions or feasible is None:
            return self._decide(sg, state, goal, feasible, frozenset()).decision
        start = time.perf_counter()
        d = self._decide_checked(sg, state, goal, feasible, start)
        self._deciding = (goal, state, d.action) if d.action is not None else None
        return d

    def _decide_checked(
        self,
        sg: GeometricSceneGraph,
        state: SymbolicSceneGraph,
        goal: Goal,
        feasible: Feasibility,
        start: float,
    ) -> Decision:
        if self._queued:
            queued = self._next_queued(sg, feasible, start)
            if queued is not None:
                return queued
        repeats = self._repeats(goal, state)
        d, tried, task_seconds = self._ask(sg, state, goal, feasible, repeats)
        if d.action is None and not tried and repeats:  # nothing but the repeats: as without
            d, tried, more = self._ask(sg, state, goal, feasible, [])
            task_seconds += more
        stuck = d.action is None and not tried and self.rules.stuck_goal_literals
        if stuck:
            d, tried = self._goal_literals(sg, state, goal, feasible, d)
        if tried:
            cleared = self._clear(sg, state, goal, tried, feasible)
            if cleared is not None:
                d = cleared
            elif not stuck:  # the planner's first choice, as without checks
                d = tried[0].decision
                if d.params is not None:  # the generator's memory back on this action
                    self.motion.propose(sg, d.action, tried[0].following, feasible)
        motion_seconds = time.perf_counter() - start - task_seconds
        return replace(d, task_seconds=task_seconds, motion_seconds=motion_seconds)

    def _repeats(self, goal: Goal, state: SymbolicSceneGraph) -> list[Action]:
        """The actions refused for having succeeded from this very state (`refuse_repeats`)."""
        if not self.rules.refuse_repeats:
            return []
        return sorted(self._succeeded.get((goal, state), ()), key=str)

    def _goal_literals(
        self,
        sg: GeometricSceneGraph,
        state: SymbolicSceneGraph,
        goal: Goal,
        feasible: Feasibility,
        stuck: Decision,
    ) -> tuple[Decision, list[_Choice]]:
        """`stuck_goal_literals`: the first action offered for a goal literal that passes the
        checks (none failing then), or the planner's `stuck` decision and those that failed."""
        tried: list[_Choice] = []
        note = f"the task planner found nothing ({stuck.note}): a goal literal's action"
        for offer in goal_actions(state, goal, sg.held)[: REFUSALS + 1]:
            params = self.motion.propose(sg, offer.action, offer.following, feasible)
            d = Decision(offer.action, params, 0.0, 0.0, note, offer.subgoal)
            if self._carried_out(sg, d, offer.following, feasible):
                return d, []
            tried.append(_Choice(d, offer.action, offer.following))
        return stuck, tried

    def _ask(
        self,
        sg: GeometricSceneGraph,
        state: SymbolicSceneGraph,
        goal: Goal,
        feasible: Feasibility,
        refused: list[Action],
    ) -> tuple[Decision, list[_Choice], float]:
        """The planner asked until an action passes its check, `refused` and those failing it
        refused (up to REFUSALS asks past the first): the last decision, the choices that
        failed (none once one passes) and the task level's seconds."""
        refused = list(refused)
        tried: list[_Choice] = []
        task_seconds = 0.0
        for _ in range(REFUSALS + 1):
            choice = self._decide(sg, state, goal, feasible, frozenset(refused))
            d = choice.decision
            task_seconds += d.task_seconds
            if choice.named is None:
                break
            if self._carried_out(sg, d, choice.following, feasible):
                return d, [], task_seconds
            tried.append(choice)
            refused.append(choice.named)
        return d, tried, task_seconds

    def _decide(
        self,
        sg: GeometricSceneGraph,
        state: SymbolicSceneGraph,
        goal: Goal,
        feasible: Feasibility | None,
        refused: frozenset[Action],
    ) -> _Choice:
        """The planner's next action (never one of `refused`) with its parameters."""
        # a planner is asked with refusals only when there are some (not every one takes them)
        ask = self.planner.next_action
        task = ask(state, goal, refused) if refused else ask(state, goal)
        if task.action is None:
            return _Choice(Decision(None, None, task.seconds, 0.0, task.note), None, None)
        start = time.perf_counter()
        action, subgoal = task.action, task.subgoal
        params = self.motion.propose(sg, action, task.following, feasible)
        give_up = params is None and isinstance(action, Push) and sg.held is None
        if give_up and self.rules.push_give_up:
            # No push works from where the object stands (a generator that gives up, the
            # geometric sampler): take it up, so that the task level puts it down elsewhere
            # in the region, where the generator will not put it again.
            action, subgoal = Pick(action.obj), in_grasp(action.obj)
            params = self.motion.propose(sg, action, None, feasible)
        note = "" if params else f"every parameter choice for {action} failed"
        seconds = time.perf_counter() - start
        decision = Decision(action, params, task.seconds, seconds, note, subgoal)
        following = task.following if action == task.action else None
        return _Choice(decision, task.action, following)

    def _carried_out(
        self,
        sg: GeometricSceneGraph,
        d: Decision,
        following: Action | None,
        feasible: Feasibility,
    ) -> bool:
        """Whether the decision's primitive plans in the model of the scene and, for a pick
        followed by a place or a stack, whether that plans once the pick is done."""
        if d.params is None or not feasible(d.params):
            return False
        trial_of = getattr(feasible, "trial", None)  # a model to try primitives in
        if not isinstance(d.action, Pick) or following is None or trial_of is None:
            return True
        with trial_of() as trial:
            ok = follows(trial, d.params, following, self._proposer(feasible), feasible, sg.world)
        self.motion.propose(sg, d.action, following, feasible)  # its memory back in this scene
        return ok

    def _clear(
        self,
        sg: GeometricSceneGraph,
        state: SymbolicSceneGraph,
        goal: Goal,
        tried: list[_Choice],
        feasible: Feasibility,
    ) -> Decision | None:
        """The first move of a way cleared for a refused action, if clearing is on, its budget
        not spent, and a way is found; the rest is queued."""
        if not self.clear_way or self._clearings >= CLEARINGS:
            return None
        blocked = [(c.decision.action, c.following) for c in tried]
        found = find_clearing(sg, state, goal, blocked, self._proposer(feasible), feasible)
        if found is None:
            return None
        self._clearings += 1
        for n in found.moves:
            self._queued += [(Pick(n), None), (Place(n, found.target), None)]
        self._queued.append((found.action, found.following))
        return self._next_queued(sg, feasible, time.perf_counter())

    def _proposer(self, feasible: Feasibility):
        """The motion generator's proposals, dry-run by `feasible`, as `clearing` asks them."""
        return lambda sg, action, following: self.motion.propose(sg, action, following, feasible)

    def _next_queued(
        self, sg: GeometricSceneGraph, feasible: Feasibility | None, start: float
    ) -> Decision | None:
        """The next action of a way being cleared, with parameters proposed in this scene; None
        (and nothing left queued) where the scene is not as the way expects or the generator
        offers nothing: the task planner decides again."""
        action, following = self._queued.pop(0)
        expected_held = action.obj if isinstance(action, Place) else None
        params = None
        if sg.held == expected_held:
            params = self.motion.propose(sg, action, following, feasible)
        if params is None:
            self._queued = []
            return None
        subgoal = (
            on(action.obj, action.target) if isinstance(action, Place) else in_grasp(action.obj)
        )
        note = f"clearing the way for {self._queued[-1][0]}" if self._queued else "way cleared"
        return Decision(action, params, 0.0, time.perf_counter() - start, note, subgoal)

    def observe(self, params: PrimitiveParams, outcome: Outcome) -> None:
        if self._deciding is not None and outcome.ok:
            goal, state, action = self._deciding
            self._succeeded.setdefault((goal, state), set()).add(action)
        self._deciding = None
        self.motion.observe(params, outcome)
