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

from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.robot import ARM, HAND, Panda

ou.setLogLevel(ou.LOG_ERROR)
OMPL_SEED = 20210530

# Checked paths keep this far from obstacles, so that contacts between the checks spaced STEP
# apart stay shallow. Transit and transfer motions are kinematic (a graze moves nothing), and
# the approach poses at the ends of a path must pass the same margin: 5 cm measured too strict
# there, failing grasps beside close neighbours.
SAFETY_MARGIN = 0.002
STEP = 0.02  # rad between collision checks along a joint-space segment
RRT_CHECKS = 6000  # collision checks a tree search may spend (about 2 s)
SHORTCUT_STEPS = 60


class CollisionChecker:
    """Whether the arm (and the object it holds) at a configuration touches anything.

    Args:
        robot: the arm; `set_q` moves a held object along.
        obstacles: bodies the arm and held object must keep `margin` away from.
        self_pairs: link pairs of the arm checked against each other.
    """

    def __init__(
        self, robot: Panda, obstacles: Iterable[int], margin: float = SAFETY_MARGIN
    ) -> None:
        self.robot = robot
        self.bc = robot.bc
        self.obstacles = tuple(obstacles)
        self.margin = margin
        self.self_pairs = _self_collision_pairs(robot)

    def collides(self, q: np.ndarray) -> bool:
        self.robot.set_q(q)
        bc, arm, held = self.bc, self.robot.body, self.robot.held_body
        for a, b in self.self_pairs:
            if bc.getClosestPoints(arm, arm, 0.0, a, b):
                return True
        for body in self.obstacles:
            if body == held:
                continue
            for pt in bc.getClosestPoints(arm, body, self.margin):
                if pt[3] > 0:  # link 0 and the base stand on the table by design
                    return True
            if held is not None and bc.getClosestPoints(held, body, self.margin):
                return True
        return False

    def hand_collides(self, q: np.ndarray) -> bool:
        """Whether the hand or its fingers at q come within the margin of an obstacle."""
        self.robot.set_q(q)
        bc, arm = self.bc, self.robot.body
        return any(
            bc.getClosestPoints(arm, body, self.margin, linkIndexA=link)
            for body in self.obstacles
            for link in HAND
        )

    def held_collides_at(self, pose: Pose) -> bool:
        """Whether the held object, put at `pose` (the arm left where it is), comes within the
        margin of an obstacle. It is put back after."""
        bc, held = self.bc, self.robot.held_body
        pos, orn = bc.getBasePositionAndOrientation(held)
        bc.resetBasePositionAndOrientation(held, pose.position, pose.orientation)
        try:
            return any(
                bc.getClosestPoints(held, body, self.margin)
                for body in self.obstacles
                if body != held
            )
        finally:
            bc.resetBasePositionAndOrientation(held, pos, orn)

    def segment_free(self, q0: np.ndarray, q1: np.ndarray) -> bool:
        n = max(1, int(np.ceil(np.max(np.abs(q1 - q0)) / STEP)))
        return not any(self.collides(q0 + (q1 - q0) * (i / n)) for i in range(1, n + 1))


def _self_collision_pairs(robot: Panda) -> list[tuple[int, int]]:
    """Non-adjacent link pairs that can meet: the hand and forearm against the upper arm."""
    return [(a, b) for a in (6, 7, 8, 9, 10) for b in (0, 1, 2) if b < a - 1]


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
