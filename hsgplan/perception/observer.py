"""f_p in the loop: the scene graph the agent plans on, from the fixed cameras' images.

Every observation renders the fixed views (`perception.synthetic.VIEWS`, the scene's own look),
runs the pose estimator and names what it found. The goal names object instances, so the
observer keeps a track of each: detections of a kind (cans, boxes) are given to that kind's
objects by an optimal assignment on the type f_p named and the distance to where each object
was last seen (`assign`). Tracks start where the scene was staged (the goal's names must refer
to something; only look-alike duplicates need it), and an object no view found this time keeps
its last pose and is reported unseen; what was found is then made to rest again with the unseen
objects where they are believed as supports too (a can put down on a butter hides it from
every view, and would otherwise be seen sunk onto the shelf under it). The object in the
hand is the robot's own knowledge: its pose is the gripper's (the arm's kinematics and the
grasp), not an estimate; and one let go since the last look was last seen where the hand let
it go (`Panda.released`), not where it was carried.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
from scipy.optimize import linear_sum_assignment

from hsgplan.domain.objects import object_type, type_of
from hsgplan.domain.world import OBJECT_TYPES
from hsgplan.perception.estimator import Detection, PoseEstimator
from hsgplan.perception.synthetic import VIEWS
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.observer import Seen
from hsgplan.sim.render import Camera
from hsgplan.sim.scene import Scene

# A detection f_p named another type is only an object's if it is within this of where the
# object was last seen (within `STILL` if a single view saw it).
TRACK_DISTANCE = 0.3  # m
# The cost, in metres of distance, of a detection f_p named another type. Small: within a
# couple of centimetres where an object was is a surer sign of which it is than the colour at
# its centroid, which a look-alike stacked on it lends it (at 3 cm, a box put down on its
# look-alike took the one detection of the pair and the one beneath kept its place: both in one).
MISMATCH = 0.01
FORBIDDEN = 1e6
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
        self._held: str | None = None

    @staticmethod
    def load(folder: Path) -> RgbObserver:
        return RgbObserver(PoseEstimator.load(folder))

    def reset(self, scene: Scene) -> None:
        self._last = scene.poses()
        self._held = scene.held()

    def observe(self, scene: Scene) -> Seen:
        images = np.stack([camera.capture(scene.bc) for camera in self.cameras])
        detections = self.estimator.detect(images, self.cameras)
        held = scene.held()
        let_go = self._held if self._held not in (None, held) else None
        released = scene.robot.released
        if let_go is not None and released and released[0] == scene.bodies[let_go]:
            # last seen in the hand: it is where the hand let it go, which the robot knows
            self._last[let_go] = released[1]
        self._held = held
        last = {o: p for o, p in self._last.items() if o != held}
        rest = self.estimator.rest if self.estimator.settled else None
        poses, unseen = tracked(detections, last, rest)
        if held is not None:
            poses[held] = scene.pose(held)
        self._last = {o: poses[o] for o in self._last}
        return Seen(GeometricSceneGraph.from_poses(self._last, held=held), unseen)


def tracked(
    detections: list[Detection],
    last: dict[str, Pose],
    rest: Callable[[list[Detection], list[tuple[str, Pose]], dict[int, Pose]], list[Detection]]
    | None = None,
) -> tuple[dict[str, Pose], tuple[str, ...]]:
    """Every object's pose (by its last pose `last`) and those no detection was given
    (`assigned`), which keep their last poses; with `rest` (`PoseEstimator.rest`), the
    detections are made to rest again with the unseen objects as supports, a lone view's at
    the place on its line of sight nearest where its object was (`along_ray_near`), and given
    again."""
    found = assigned(detections, last)
    unseen = tuple(o for o in last if o not in found)
    index = {id(d): k for k, d in enumerate(detections)}
    near = {index[id(d)]: last[o] for o, d in found.items() if len(d.rays) == 1}
    if (unseen or near) and rest is not None:
        fixed = [(type_of(o), last[o]) for o in unseen]
        found = assigned(rest(detections, fixed, near), last)
        unseen = tuple(o for o in last if o not in found)
    poses = {o: d.pose for o, d in found.items()}
    return poses | {o: last[o] for o in unseen}, unseen


def assign(detections: list[Detection], last: dict[str, Pose]) -> dict[str, Pose]:
    """Each object (by its last pose) and the pose of the detection it gets (`assigned`)."""
    return {o: d.pose for o, d in assigned(detections, last).items()}


def assigned(detections: list[Detection], last: dict[str, Pose]) -> dict[str, Detection]:
    """Each object (by its last pose) and the detection it gets, kind by kind (cans,
    boxes): the assignment of least total cost, a detection's cost for an object being its
    distance from the object's last pose counted up to `STILL`, plus `MISMATCH` when f_p named
    it another type (look-alikes stacked can show one another's colour: an object that did not
    move is known by where it is), less a hundredth of its score and plus a thousandth of the
    distance to break ties. A detection of another type further than `TRACK_DISTANCE` from an
    object's last pose is never that object, nor is one of another type that a single view saw
    further than `STILL`: two weak signs, where a look-alike phantom is likelier than a moved
    object."""
    out: dict[str, Detection] = {}
    for kind in sorted({object_type(o).kind for o in last}):
        objects = [o for o in last if object_type(o).kind is kind]
        found = [d for d in detections if OBJECT_TYPES[d.type_name].kind is kind]
        if not found:
            continue
        cost = np.empty((len(objects), len(found)))
        allowed = np.empty_like(cost, dtype=bool)
        for i, o in enumerate(objects):
            for j, d in enumerate(found):
                far = float(np.linalg.norm(np.subtract(d.pose.position, last[o].position)))
                same = d.type_name == type_of(o)
                allowed[i, j] = same or far < (TRACK_DISTANCE if d.views > 1 else STILL)
                cost[i, j] = min(far, STILL) + (0.0 if same else MISMATCH)
                cost[i, j] += 1e-3 * far - 1e-2 * d.score
        cost[~allowed] = FORBIDDEN
        for i, j in zip(*linear_sum_assignment(cost), strict=True):
            if allowed[i, j]:
                out[objects[i]] = found[j]
    return out
