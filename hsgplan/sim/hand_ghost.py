"""The hand's shape on its own, to ask what a hand at a TCP pose would touch without solving
for the arm's joints.

Where the hand and its fingers are depends on the TCP pose alone, so whether they touch a shelf
along a push line can be known before any inverse kinematics: a ghost copy of their collision
shapes (the fingers at one opening) is put at each pose and asked. The ghost is a static body
that takes no part in physics (it collides with nothing; only distance queries see it) and has
no visual shape.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.robot import HAND, Panda

PARKED = (0.0, 0.0, -5.0)  # m: out of everyone's way between queries


class HandGhost:
    """The hand and fingers of `robot`, fingers at `opening`, as one body.

    Args:
        robot: the arm whose hand is copied (its collision shapes and their offsets).
        opening: the finger opening the copy is made at, in metres.
    """

    def __init__(self, robot: Panda, opening: float) -> None:
        bc = self.bc = robot.bc
        shapes = []
        with robot.preserved():
            robot.set_fingers(opening)
            tcp = robot.tcp()
            for link in HAND:
                com = bc.getLinkState(robot.body, link, computeForwardKinematics=True)
                for shape in bc.getCollisionShapeData(robot.body, link):
                    # Shape frames are given in the link's inertial frame.
                    local = Pose(tuple(shape[5]), tuple(shape[6]))
                    at = Pose(tuple(com[0]), tuple(com[1])).compose(local).relative_to(tcp)
                    shapes.append((shape[2], shape[3], shape[4].decode(), at))
        shape = bc.createCollisionShapeArray(
            shapeTypes=[s[0] for s in shapes],
            meshScales=[list(s[1]) for s in shapes],
            fileNames=[s[2] for s in shapes],
            collisionFramePositions=[list(s[3].position) for s in shapes],
            collisionFrameOrientations=[list(s[3].orientation) for s in shapes],
        )
        self.body = bc.createMultiBody(0, shape, -1, PARKED, useMaximalCoordinates=True)
        bc.setCollisionFilterGroupMask(self.body, -1, 0, 0)

    def touches(self, tcps: Iterable[Pose], obstacles: tuple[int, ...], margin: float) -> bool:
        """Whether the hand, with the TCP at any of `tcps` (asked in order, stopping at the
        first touch), comes within `margin` of an obstacle."""
        bc = self.bc
        boxes = np.array([bc.getAABB(b) for b in obstacles]).reshape(-1, 2, 3)
        lo, hi = boxes[:, 0] - margin, boxes[:, 1] + margin
        try:
            for tcp in tcps:
                bc.resetBasePositionAndOrientation(self.body, tcp.position, tcp.orientation)
                g_lo, g_hi = bc.getAABB(self.body)
                near = ((lo <= g_hi) & (hi >= g_lo)).all(axis=1)
                if any(
                    bc.getClosestPoints(self.body, obstacles[i], margin)
                    for i in np.flatnonzero(near)
                ):
                    return True
            return False
        finally:
            bc.resetBasePositionAndOrientation(self.body, PARKED, (0, 0, 0, 1))
