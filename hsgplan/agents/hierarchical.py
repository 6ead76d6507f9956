"""The one agent class: a task planner and a motion generator, composed as the paper composes
them. The task planner reads the symbolic scene graph s_s and names the next action and the
subgoal it serves; the motion generator reads the geometric scene graph s_g and chooses the
action's parameters."""

from __future__ import annotations

import time

from hsgplan.agents.base import Decision
from hsgplan.domain.actions import Pick, Push
from hsgplan.domain.goals import Goal
from hsgplan.domain.parameters import PrimitiveParams
from hsgplan.domain.predicates import in_grasp
from hsgplan.domain.recovery import ALL_RULES, RecoveryRules
from hsgplan.motion.interface import Feasibility, MotionGenerator
from hsgplan.planning.base import TaskPlanner
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.sim.outcome import Outcome


class HierarchicalAgent:
    """Args:
    name: what episodes record as the agent.
    planner: the task level (`hsgplan.planning.base.TaskPlanner`).
    motion: the motion level (`hsgplan.motion.interface.MotionGenerator`).
    rules: the recovery rules in force (`hsgplan.domain.recovery`); this class applies the
        task half of `push_give_up` (a push with no parameters becomes a pick).
    """

    def __init__(
        self,
        name: str,
        planner: TaskPlanner,
        motion: MotionGenerator,
        rules: RecoveryRules = ALL_RULES,
    ) -> None:
        self.name = name
        self.planner = planner
        self.motion = motion
        self.rules = rules

    def reset(self, goal: Goal, seed: int) -> None:
        self.planner.reset(goal, seed)
        self.motion.reset(seed)

    def decide(
        self,
        sg: GeometricSceneGraph,
        state: SymbolicSceneGraph,
        goal: Goal,
        feasible: Feasibility | None = None,
    ) -> Decision:
        task = self.planner.next_action(state, goal)
        if task.action is None:
            return Decision(None, None, task.seconds, 0.0, task.note)
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
        return Decision(action, params, task.seconds, seconds, note, subgoal)

    def observe(self, params: PrimitiveParams, outcome: Outcome) -> None:
        self.motion.observe(params, outcome)
