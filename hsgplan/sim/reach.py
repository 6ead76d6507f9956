"""Where a step's arm could have touched anything, by the robot's own model: the boxes its links
swept along the joints a plan drove them through. A camera observer's verdict on a step reads
a neighbour's believed move as the step's doing only where the arm, what it carried or what it
pushed came near it (the perception rule `near_moves_only`, `hsgplan.domain.recovery`); a
belief that moved farther off was put right by the new look.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np

from hsgplan.sim.motion import densify
from hsgplan.sim.motion_plans import MotionPlan
from hsgplan.sim.robot import Panda
from hsgplan.sim.sensing import Box

# An object whose centre is farther than this from every swept box (and from the acted object's
# track) was not touched by the step: more than the largest grocery's half extent (6.3 cm) plus
# a finger's width and the belief's own spread. Chosen a priori, not tuned.
REACH_MARGIN = 0.10  # m
# Joint-space step between the configurations the sweep samples: 0.05 rad moves a link 0.8 m
# from the base by 4 cm, well inside the margin.
SWEEP_STEP = 0.05  # rad


def driven(plan: MotionPlan) -> list[np.ndarray]:
    """The joints a plan drives the arm through, densely enough for the sweep: its path, the
    approach (and the retreat back along it) and a push's line."""
    waypoints = [*plan.path, plan.q_above, *plan.descent, plan.q_at, *plan.line]
    return densify([np.asarray(q, dtype=float) for q in waypoints], SWEEP_STEP)


def swept_boxes(robot: Panda, joints: Iterable[np.ndarray], below: float = 0.0) -> list[Box]:
    """Every link's box at each of `joints` (the robot is put back after), each grown down by
    `below` (m): what a top-down grasp carries hangs under the hand by up to its height."""
    boxes = []
    with robot.preserved():
        for q in joints:
            robot.set_q_for_query(q)
            for b in robot.boxes():
                low = (b.low[0], b.low[1], b.low[2] - below)
                boxes.append(Box(low, b.high))
    return boxes


def segment_distance(point: Sequence[float], a: Sequence[float], b: Sequence[float]) -> float:
    """The distance (m) from a point to the segment from `a` to `b`."""
    p, a, b = (np.asarray(v, dtype=float) for v in (point, a, b))
    ab = b - a
    t = 0.0 if not ab.any() else float(np.clip(np.dot(p - a, ab) / np.dot(ab, ab), 0.0, 1.0))
    return float(np.linalg.norm(p - (a + t * ab)))


def near(
    points: Sequence[Sequence[float]],
    boxes: Sequence[Box],
    track: tuple[Sequence[float], Sequence[float]] | None,
    margin: float = REACH_MARGIN,
) -> bool:
    """Whether any of `points` lies within `margin` of a box or of the `track` (the acted
    object's centre before and after the step)."""
    if track is not None and any(segment_distance(p, *track) <= margin for p in points):
        return True
    if not boxes or not points:
        return False
    low = np.array([b.low for b in boxes])
    high = np.array([b.high for b in boxes])
    p = np.asarray(points, dtype=float)[:, None, :]
    gap = np.maximum(np.maximum(low - p, p - high), 0.0)
    return bool((np.linalg.norm(gap, axis=-1) <= margin).any())
