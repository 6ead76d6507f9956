"""Whether the arm, or what it holds, touches anything: the collision checks of planning.

PyBullet answers "how close are these two bodies" one pair of bodies per call, and a check of
the arm against a kitchen scene is ~30 such calls (15 obstacles, 15 pairs of its own links),
almost all of them between things half a metre apart. Each link is therefore bounded by a
sphere around its centre of mass, each obstacle by its axis-aligned box, and PyBullet is asked
only about the pairs whose bounds come within the margin. The bounds are conservative, so the
verdict is the one asking about every pair would give, for a fraction of the calls.
"""

from __future__ import annotations

import numpy as np

from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.robot import Panda

# Checked paths keep this far from obstacles, so that contacts between the checks spaced STEP
# apart stay shallow; the arm runs them under physics, so a graze pushes what it touches. The
# approach poses at the ends of a path must pass the same margin: 5 cm measured too strict
# there, failing grasps beside close neighbours.
SAFETY_MARGIN = 0.002
STEP = 0.02  # rad between collision checks along a joint-space segment
BOUND_PAD = 0.01  # m added to every bound: collision margins and rounding stay inside them
# Link pairs of the arm that can meet: the hand and forearm against the upper arm.
SELF_PAIRS = tuple((a, b) for a in (6, 7, 8, 9, 10) for b in (0, 1, 2) if b < a - 1)


class LinkBounds:
    """A sphere around each of the arm's links that has a collision shape, measured once.

    The sphere is centred on the link's centre of mass and reaches the farthest corner of the
    link's bounding box (which contains the link's shape, whatever its orientation) plus a pad.
    """

    def __init__(self, robot: Panda) -> None:
        bc, body = robot.bc, robot.body
        links = [j for j in range(bc.getNumJoints(body)) if bc.getCollisionShapeData(body, j)]
        radii = []
        for j in links:
            com = np.array(bc.getLinkState(body, j, computeForwardKinematics=True)[0])
            lo, hi = (np.array(v) for v in bc.getAABB(body, j))
            corners = np.array(
                [[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
            )
            radii.append(float(np.max(np.linalg.norm(corners - com, axis=1))) + BOUND_PAD)
        self.links = tuple(links)
        self.radii = np.array(radii)
        self.row = {j: i for i, j in enumerate(links)}

    def centers(self, robot: Panda) -> np.ndarray:
        """(links, 3): each bounded link's centre of mass, with the arm where it is now."""
        states = robot.bc.getLinkStates(robot.body, self.links, computeForwardKinematics=True)
        return np.array([s[0] for s in states])


def _bounds(robot: Panda) -> LinkBounds:
    # Measured once per arm: a checker is made for every query, the arm's links never change.
    if not hasattr(robot, "_link_bounds"):
        robot._link_bounds = LinkBounds(robot)
    return robot._link_bounds


class CollisionChecker:
    """Whether the arm (and the object it holds) at a configuration touches anything.

    Args:
        robot: the arm; `set_q` moves a held object along.
        obstacles: bodies the arm and held object must keep `margin` away from; they stay
            where they are while the checker is used.
        margin: the clearance in metres (0: touching counts, nothing less).
    """

    def __init__(self, robot: Panda, obstacles, margin: float = SAFETY_MARGIN) -> None:
        self.robot = robot
        self.bc = robot.bc
        self.margin = margin
        held = robot.held_body
        # A held object moves with the hand: it is never an obstacle to itself.
        self.obstacles = tuple(b for b in obstacles if b != held)
        boxes = [self.bc.getAABB(b) for b in self.obstacles]
        self._lo = np.array([b[0] for b in boxes]).reshape(-1, 3) - BOUND_PAD
        self._hi = np.array([b[1] for b in boxes]).reshape(-1, 3) + BOUND_PAD
        self.links = _bounds(robot)
        rows, radii = self.links.row, self.links.radii
        # Link 0 and the base stand on the table by design: links from 1 are checked (the
        # rows are in link order, so they are the rows from the first such link on).
        self._first = next(i for i, j in enumerate(self.links.links) if j >= 1)
        # Each box grown by each checked link's reach, axis first, so that a check is a few
        # operations on small arrays (numpy's per-call cost dominates at these sizes).
        reach = radii[self._first :][None, :, None] + margin
        self._mid = ((self._lo + self._hi) / 2).T[:, None, :]
        self._half = ((self._hi - self._lo) / 2).T[:, None, :] + reach
        # Squared reach of every pair of rows, -1 for the pairs that are not checked.
        self._pair_reach = np.full((len(radii), len(radii)), -1.0)
        for a, b in SELF_PAIRS:
            if a in rows and b in rows:
                self._pair_reach[rows[a], rows[b]] = (radii[rows[a]] + radii[rows[b]]) ** 2
        self._held_radius = 0.0
        if held is not None:
            lo, hi = (np.array(v) for v in self.bc.getAABB(held))
            centre = np.array(self.bc.getBasePositionAndOrientation(held)[0])
            self._held_radius = (
                float(np.linalg.norm(np.maximum(np.abs(lo - centre), np.abs(hi - centre))))
                + BOUND_PAD
            )

    def _near(self, centers: np.ndarray, radii: np.ndarray) -> np.ndarray:
        """(spheres, obstacles): whether each sphere comes within the margin of each box."""
        c = centers[:, None, :]
        d = c - np.clip(c, self._lo, self._hi)
        reach = radii + self.margin
        return np.einsum("kmi,kmi->km", d, d) <= (reach * reach)[:, None]

    def collides(self, q: np.ndarray) -> bool:
        self.robot.set_q_for_query(q)
        bc, arm = self.bc, self.robot.body
        links, c = self.links.links, self.links.centers(self.robot)
        # Pairs in SELF_PAIRS order and link-then-obstacle order: the same calls, in the same
        # order, as asking pair by pair (PyBullet's later answers depend on its call history).
        d = c[:, None, :] - c[None, :, :]
        near = np.einsum("abi,abi->ab", d, d) <= self._pair_reach
        if near.any():
            for a, b in zip(*np.nonzero(near), strict=True):
                if bc.getClosestPoints(arm, arm, 0.0, links[a], links[b]):
                    return True
        t = np.abs(c[self._first :].T[:, :, None] - self._mid) - self._half
        near = np.maximum(np.maximum(t[0], t[1]), t[2]) <= 0.0
        if near.any():
            for i, o in zip(*np.nonzero(near), strict=True):
                if bc.getClosestPoints(arm, self.obstacles[o], self.margin, links[self._first + i]):
                    return True
        held = self.robot.held_body
        if held is None:
            return False
        centre = np.array(bc.getBasePositionAndOrientation(held)[0])[None]
        near = self._near(centre, np.array([self._held_radius]))[0]
        return any(
            bc.getClosestPoints(held, self.obstacles[o], self.margin) for o in np.flatnonzero(near)
        )

    def held_collides_at(self, pose: Pose) -> bool:
        """Whether the held object, put at `pose` (the arm left where it is), comes within the
        margin of an obstacle. It is put back after."""
        bc, held = self.bc, self.robot.held_body
        pos, orn = bc.getBasePositionAndOrientation(held)
        bc.resetBasePositionAndOrientation(held, pose.position, pose.orientation)
        try:
            return any(bc.getClosestPoints(held, body, self.margin) for body in self.obstacles)
        finally:
            bc.resetBasePositionAndOrientation(held, pos, orn)

    def segment_free(self, q0: np.ndarray, q1: np.ndarray) -> bool:
        n = max(1, int(np.ceil(np.max(np.abs(q1 - q0)) / STEP)))
        return not any(self.collides(q0 + (q1 - q0) * (i / n)) for i in range(1, n + 1))
