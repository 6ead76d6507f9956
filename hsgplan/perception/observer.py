"""f_p in the loop: the scene graph the agent plans on, from the fixed cameras' images.

Every observation renders the three views (`perception.synthetic.VIEWS`, the scene's own look),
runs the pose estimator and names what it found. The goal names object instances, so the
observer keeps a track of each: a detection of a type is given to that type's objects by an
optimal assignment on the distance to where each was last seen. Tracks start where the scene
was staged (the goal's names must refer to something; only look-alike duplicates need it), and
an object no view found this time keeps its last pose and is reported unseen. The object in the
hand is the robot's own knowledge: its pose is the gripper's (the arm's kinematics and the
grasp), not an estimate.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.optimize import linear_sum_assignment

from hsgplan.domain.objects import type_of
from hsgplan.perception.estimator import Detection, PoseEstimator
from hsgplan.perception.synthetic import VIEWS
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.observer import Seen
from hsgplan.sim.render import Camera
from hsgplan.sim.scene import Scene

# With more detections of a type than objects (a false one among them), a detection further
# than this from an object's last pose is not that object. Otherwise every detection is some
# object's: a duplicate just put down elsewhere is found by elimination.
TRACK_DISTANCE = 0.3  # m
# Beyond this a detection is as far from an object's last pose as any other: most objects stay
# where they were, so the assignment keeps as many as it can within it, and a far-moved one
# does not drag the others to its detection to shorten its own distance.
STILL = 0.05  # m


class RgbObserver:
    """Args:
    estimator: the trained pose estimator.
    cameras: the fixed views it was trained on.
    """

    name = "rgb"

    def __init__(self, estimator: PoseEstimator, cameras: tuple[Camera, ...] = VIEWS) -> None:
        self.estimator = estimator
        self.cameras = cameras
        self._last: dict[str, Pose] = {}

    @staticmethod
    def load(folder: Path) -> RgbObserver:
        return RgbObserver(PoseEstimator.load(folder))

    def reset(self, scene: Scene) -> None:
        self._last = scene.poses()

    def observe(self, scene: Scene) -> Seen:
        images = np.stack([camera.capture(scene.bc) for camera in self.cameras])
        detections = self.estimator.detect(images, self.cameras)
        held = scene.held()
        poses = assign(detections, {o: p for o, p in self._last.items() if o != held})
        unseen = tuple(o for o in self._last if o != held and o not in poses)
        for o in unseen:
            poses[o] = self._last[o]
        if held is not None:
            poses[held] = scene.pose(held)
        self._last = {o: poses[o] for o in self._last}
        return Seen(GeometricSceneGraph.from_poses(self._last, held=held), unseen)


def assign(detections: list[Detection], last: dict[str, Pose]) -> dict[str, Pose]:
    """Each object (by its last pose) and the pose of the detection it gets, type by type: the
    assignment with the least total distance, each distance counted up to `STILL` (and a
    thousandth beyond, to break ties); a lone object of its type takes its type's
    strongest detection wherever it is."""
    out: dict[str, Pose] = {}
    for t in sorted({type_of(o) for o in last}):
        objects = [o for o in last if type_of(o) == t]
        found = sorted((d for d in detections if d.type_name == t), key=lambda d: -d.score)
        if not found:
            continue
        if len(objects) == 1:
            out[objects[0]] = found[0].pose
            continue
        cost = np.array(
            [
                [np.linalg.norm(np.subtract(d.pose.position, last[o].position)) for d in found]
                for o in objects
            ]
        )
        gate = TRACK_DISTANCE if len(found) > len(objects) else np.inf
        saturated = np.minimum(cost, STILL) + 1e-3 * cost
        for i, j in zip(*linear_sum_assignment(saturated), strict=True):
            if cost[i, j] < gate:
                out[objects[i]] = found[j].pose
    return out
