"""Joint-space motion planning: OMPL's RRTConnect with PyBullet as the collision checker.

A straight joint-space segment is tried first (most transit motions above the table are free),
then the caller's detours, and RRTConnect only when they all collide. Every query re-seeds
OMPL's seed generator with the same constant before its planner and simplifier draw their
generators, so a query's path depends on its inputs alone (measured: repeated queries give
identical paths); the search spends a budget of collision checks and simplification counts its
steps, rather than either spending seconds, for the same reason.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence

import numpy as np
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from hsgplan.sim.collision import STEP, CollisionChecker
from hsgplan.sim.robot import ARM

ou.setLogLevel(ou.LOG_ERROR)
OMPL_SEED = 20210530

RRT_CHECKS = 6000  # collision checks a tree search may spend (about 2 s)
SHORTCUT_STEPS = 60


class MotionPlanner:
    """Plans collision-free joint paths for one arm."""

    def __init__(self, checker: CollisionChecker) -> None:
        self.checker = checker
        robot = checker.robot
        self.space = ob.RealVectorStateSpace(len(ARM))
        bounds = ob.RealVectorBounds(len(ARM))
        for i in range(len(ARM)):
            bounds.setLow(i, float(robot.lower[i]))
            bounds.setHigh(i, float(robot.upper[i]))
        self.space.setBounds(bounds)

    def plan(
        self, q0: np.ndarray, q1: np.ndarray, vias: Iterable[Callable[[], list[np.ndarray]]] = ()
    ) -> list[np.ndarray] | None:
        """Waypoints from q0 to q1 (both included), or None when no path is found.

        The straight segment first, then each of `vias` (made only when reached, as they may
        cost inverse kinematics) as a chain of straight segments through its waypoints, then
        RRTConnect: a few straight checks cost a fraction of a tree search.
        """
        checker = self.checker
        with checker.robot.preserved():
            if checker.collides(q0) or checker.collides(q1):
                return None
            if checker.segment_free(q0, q1):
                return [q0, q1]
            for make in vias:
                path = [q0, *make(), q1]
                if all(checker.segment_free(a, b) for a, b in zip(path, path[1:], strict=False)):
                    return path
            return self._rrt(q0, q1)

    def _rrt(self, q0: np.ndarray, q1: np.ndarray) -> list[np.ndarray] | None:
        # OMPL warns that re-seeding after the first draw is not deterministic; it is here, as
        # the generator restarts from its first seed, which is always OMPL_SEED.
        ou.setLogLevel(ou.LOG_NONE)
        ou.RNG.setSeed(OMPL_SEED)
        ou.setLogLevel(ou.LOG_ERROR)
        ss = og.SimpleSetup(self.space)
        checks = 0

        def valid(state) -> bool:
            nonlocal checks
            checks += 1
            return not self.checker.collides(_array(state))

        ss.setStateValidityChecker(valid)
        si = ss.getSpaceInformation()
        si.setStateValidityCheckingResolution(STEP / self.space.getMaximumExtent())
        ss.setPlanner(og.RRTConnect(si))
        start, goal = self.space.allocState(), self.space.allocState()
        for i in range(len(ARM)):
            start[i], goal[i] = float(q0[i]), float(q1[i])
        ss.setStartAndGoalStates(start, goal)
        # A budget of collision checks, not of seconds: on a busy machine a time budget would
        # give up on searches that an idle one finishes, and results would depend on the load.
        done = ob.PlannerTerminationCondition(lambda: checks >= RRT_CHECKS)
        if not ss.solve(done) or not ss.haveExactSolutionPath():
            return None
        path = ss.getSolutionPath()
        simplifier = og.PathSimplifier(si)
        simplifier.reduceVertices(path, SHORTCUT_STEPS, SHORTCUT_STEPS, 0.33)
        simplifier.ropeShortcutPath(path)
        return [_array(path.getState(i)) for i in range(path.getStateCount())]


def _array(state) -> np.ndarray:
    return np.array([state[i] for i in range(len(ARM))])


def densify(waypoints: Sequence[np.ndarray], step: float = STEP) -> list[np.ndarray]:
    """Intermediate configurations at most `step` apart, for execution and pictures."""
    out = [waypoints[0]]
    for a, b in zip(waypoints, waypoints[1:], strict=False):
        n = max(1, int(np.ceil(np.max(np.abs(b - a)) / step)))
        out += [a + (b - a) * (i / n) for i in range(1, n + 1)]
    return out
