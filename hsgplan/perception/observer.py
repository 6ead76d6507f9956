"""f_p in the loop: the robot's belief of where the objects are, from the fixed cameras' images.

The observer is given what a real robot has (`sim.sensing.Look`): the images, the cameras'
calibration, the arm's joints and what it knows of its own hand; and, when an episode starts, the
goal's object names (their types follow from them) and the scene's `World` (the types' sizes, the
table and the shelves: what a robot knows of its room and of what it handles). Nothing else: no
staged pose, no simulated scene. Every look runs the pose estimator and names what it found. The
goal names object instances, so the observer keeps a track of each: detections of a kind (cans,
boxes) are given to that kind's tracked objects by an optimal assignment on the type f_p named and
the distance to where each object was last seen (`assign`). An object has no pose until it is first
seen: what is left of a look's detections after the tracks took theirs is given to the objects never
seen, by type, the surest first (`first_sight`); look-alike duplicates of one type are named in the
order f_p is surest of them. An object no view found this time keeps its last pose and is reported
unseen; what was found is then made to rest again with the unseen objects where they are believed as
supports too (a can put down on a butter hides it from every view, and would otherwise be seen sunk
onto the shelf under it). The object in the hand is the robot's own knowledge: its pose is the arm's
kinematics and the grasp as planned, not an estimate, and detections at the hand are not other
objects; one let go since the last look was last seen where the hand let it go, not where it was
carried.

Each object's belief is as sure as its last sighting: one not seen this time, or seen by a
single view (whose depth along its line of sight PnP gets worst), is reported `uncertain`.

A still object keeps the better of its sightings (`steady`): where a look's detection of it lies
within `STEADY` of where it is believed and fewer views saw it than the look its belief came
from, the belief stays (the arm, standing where the last step left it, hides the object from a
view, and a box's yaw from the views left can be tens of degrees off).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path

import numpy as np
from scipy.optimize import linear_sum_assignment

from hsgplan.domain.world import World
from hsgplan.perception.detection import Detection
from hsgplan.perception.estimator import PoseEstimator
from hsgplan.perception.rules import SHIPPED, PerceptionRules
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.render import Camera
from hsgplan.sim.sensing import Look, Seen

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


# m from the held object's pose within which a detection is the hand's load or the hand: the
# robot knows where its hand is, so nothing there is another object.
HAND_RADIUS = 0.1
# m: a detection this close to an object's belief is of the object where it was (it did not move).
# On the tuning seeds (`eval world --perception rgb --protocol paper --sizes 6 --goals 30
# --seed 900`) a still box between looks seemed to move 4 to 6 mm while its yaw swung by 34 to
# 70 degrees; a move of 1 cm is what the pose targets allow.
STEADY = 0.01


class RgbObserver:
    """Args:
    estimator: the trained pose estimator.
    cameras: the fixed views it was trained on.
    steady: a still object keeps the sighting of more views (`steadied`, `STEADY`).
    name: what the episode records it as (`evaluation.observers`' names).
    """

    def __init__(
        self,
        estimator: PoseEstimator,
        cameras: tuple[Camera, ...] | None = None,
        steady: bool = True,
        name: str = "rgb",
    ) -> None:
        self.estimator = estimator
        # None: the cameras its estimator's f_p was trained with
        self.cameras = estimator.vocabulary.views if cameras is None else cameras
        self.steady = steady
        self.name = name
        self._views: dict[str, int] = {}  # the views behind each object's belief
        self.world: World | None = None  # the episode's scene (`start`)
        self._objects: tuple[str, ...] = ()
        self._last: dict[str, Pose] = {}
        # the last look's detections, the hand's left out: what a recording shows of f_p
        self.detections: tuple[Detection, ...] = ()

    @staticmethod
    def load(
        folder: Path,
        name: str = "rgb",
        steady: bool = True,
        silhouette: bool = True,
        rules: PerceptionRules = SHIPPED,
    ) -> RgbObserver:
        """The observer of an f_p checkpoint folder, through the cameras it was trained with
        (`silhouette`: its estimator checks boxes' yaws by their silhouettes,
        `perception.silhouette`; `rules`: its estimator's and tracker's, `perception.rules`)."""
        estimator = PoseEstimator.load(folder, silhouette=silhouette, rules=rules)
        return RgbObserver(estimator, estimator.vocabulary.views, steady, name)

    def start(self, objects: tuple[str, ...], world: World) -> None:
        self.world = world
        self._objects = tuple(objects)
        self._last = {}
        self._views = {}
        self.detections = ()

    def look(self, look: Look) -> Seen:
        start = time.perf_counter()
        world = self.world
        if world is None:
            raise RuntimeError("start() an episode before looking")
        detections = self.estimator.detect(look.images, look.cameras, world, look.arm)
        held = look.holding
        if look.released is not None:
            # last seen in the hand, or before a push: it is where the hand let it go, or where
            # the push's stroke ended, which the robot knows of its own motion
            name, pose = look.released
            self._last[name] = pose
            self._views[name] = 0  # not a sighting: any look is better
        if held is not None:
            detections = away_from_hand(detections, look.held_pose)
        self.detections = tuple(detections)
        known = {o: p for o, p in self._last.items() if o != held}
        rules = self.estimator.rules
        rest = partial(self.estimator.rest, world, rules=rules) if self.estimator.settled else None
        tracks = tracked(detections, known, world, rest, rules)
        never = [o for o in self._objects if o not in self._last and o != held]
        first = first_sight(tracks.left, never, self._objects, world)
        poses = tracks.poses | {o: d.pose for o, d in first.items()}
        views = {o: d.views for o, d in (tracks.found | first).items()}
        if self.steady:
            kept = steadied(tracks.found, known, self._views)
            poses |= kept
            views |= {o: self._views[o] for o in kept}
        if held is not None and look.held_pose is not None:
            poses[held] = look.held_pose
            views[held] = len(look.cameras)  # the robot's own knowledge: sure
        self._last = {o: poses[o] for o in self._objects if o in poses}
        self._views |= views
        unknown = tuple(o for o in self._objects if o not in self._last)
        uncertain = tuple(o for o in self._last if views.get(o, 0) <= 1) + unknown
        return Seen(
            GeometricSceneGraph.from_poses(self._last, held=held, world=world),
            tracks.unseen,
            unknown,
            uncertain,
            time.perf_counter() - start,
        )


def steadied(
    found: dict[str, Detection], last: dict[str, Pose], last_views: dict[str, int]
) -> dict[str, Pose]:
    """The objects whose belief `last` stays over this look's detection `found` of them: the
    detection lies within `STEADY` of the belief, and fewer views made it than the `last_views`
    behind the belief."""
    return {
        o: last[o]
        for o, d in found.items()
        if o in last
        and d.views < last_views.get(o, 0)
        and np.linalg.norm(np.subtract(d.pose.position, last[o].position)) < STEADY
    }


def away_from_hand(detections: list[Detection], hand: Pose | None) -> list[Detection]:
    """The detections measured further than `HAND_RADIUS` from the held object's pose `hand`
    (all of them without one). Where it was measured, not where it was made to rest: the held
    object's own detection, made to rest on what is under the hand, lands just past the radius,
    and was the commonest detection matching no object in scenes from inside the loop."""
    if hand is None:
        return detections
    at = np.asarray(hand.position)
    return [d for d in detections if np.linalg.norm(_measured(d) - at) > HAND_RADIUS]


def _measured(d: Detection) -> np.ndarray:
    return np.asarray((d.measured or d.pose).position)


@dataclass(frozen=True)
class Tracks:
    """A look's detections given to the tracked objects.

    Attributes:
        poses: every tracked object's pose (by its detection, else its last pose).
        unseen: tracked objects no detection was given to (their last poses kept).
        found: each object given a detection, and that detection.
        left: detections given to no tracked object.
    """

    poses: dict[str, Pose]
    unseen: tuple[str, ...]
    found: dict[str, Detection] = field(default_factory=dict)
    left: tuple[Detection, ...] = ()


def tracked(
    detections: list[Detection],
    last: dict[str, Pose],
    world: World,
    rest: Callable[[list[Detection], list[tuple[str, Pose]], dict[int, Pose]], list[Detection]]
    | None = None,
    rules: PerceptionRules = SHIPPED,
) -> Tracks:
    """Every object's pose (by its last pose `last`; their types are `world`'s) and those no
    detection was given (`assigned`), which keep their last poses; with `rest`
    (`PoseEstimator.rest`), the detections are made to rest again with the unseen objects as
    supports, a lone view's at the place on its line of sight nearest where its object was
    (`along_ray_near`), and given again."""
    found = assigned(detections, last, world, rules)
    unseen = tuple(o for o in last if o not in found)
    index = {id(d): k for k, d in enumerate(detections)}
    near = {index[id(d)]: last[o] for o, d in found.items() if len(d.rays) == 1}
    if (unseen or near) and rest is not None:
        fixed = [(world.type_of(o), last[o]) for o in unseen]
        detections = rest(detections, fixed, near)
        found = assigned(detections, last, world, rules)
        unseen = tuple(o for o in last if o not in found)
    poses = {o: d.pose for o, d in found.items()}
    taken = {id(d) for d in found.values()}
    left = tuple(d for d in detections if id(d) not in taken)
    return Tracks(poses | {o: last[o] for o in unseen}, unseen, found, left)


def first_sight(
    detections: tuple[Detection, ...], never: list[str], objects: tuple[str, ...], world: World
) -> dict[str, Detection]:
    """Objects never seen before (`never`, of the episode's `objects`), given the detections no
    tracked object took: each object (in its name's order) the detection f_p named its type,
    the surest first (more views, then the colour network's confidence, then the keypoint
    network's score); then, to an object still unseen, a detection of its kind whose type is
    none of the episode's objects' (f_p misnamed it: the scene holds the goal's objects and no
    others), the surest first. A detection of a type already seen is never a guess's: it is
    likelier that object's phantom."""
    out: dict[str, Detection] = {}
    pool = sorted(detections, key=lambda d: (-d.views, -d.type_confidence, -d.score))
    for o in never:
        d = next((d for d in pool if d.type_name == world.type_of(o)), None)
        if d is not None:
            out[o] = d
            pool.remove(d)
    present = {world.type_of(o) for o in objects}
    for o in (o for o in never if o not in out):
        kind = world.object_type(o).kind
        d = next(
            (
                d
                for d in pool
                if world.object_type(d.type_name).kind is kind and d.type_name not in present
            ),
            None,
        )
        if d is not None:
            out[o] = d
            pool.remove(d)
    return out


def assign(detections: list[Detection], last: dict[str, Pose], world: World) -> dict[str, Pose]:
    """Each object (by its last pose) and the pose of the detection it gets (`assigned`)."""
    return {o: d.pose for o, d in assigned(detections, last, world).items()}


def assigned(
    detections: list[Detection],
    last: dict[str, Pose],
    world: World,
    rules: PerceptionRules = SHIPPED,
) -> dict[str, Detection]:
    """Each object (by its last pose) and the detection it gets, kind by kind (cans,
    boxes): the assignment of least total cost, a detection's cost for an object being its
    distance from the object's last pose counted up to `STILL`, plus `MISMATCH` when f_p named
    it another type (look-alikes stacked can show one another's colour: an object that did not
    move is known by where it is), less a hundredth of its score and plus a thousandth of the
    distance to break ties. A detection of another type further than `TRACK_DISTANCE` from an
    object's last pose is never that object, nor is one of another type that a single view saw
    further than `STILL`: two weak signs, where a look-alike phantom is likelier than a moved
    object. (`rules` may set the first distance and switch the second off: `lone_still`.)"""
    lone = STILL if rules.lone_still else rules.track_distance
    out: dict[str, Detection] = {}
    for kind in sorted({world.object_type(o).kind for o in last}):
        objects = [o for o in last if world.object_type(o).kind is kind]
        found = [d for d in detections if world.object_type(d.type_name).kind is kind]
        if not found:
            continue
        cost = np.empty((len(objects), len(found)))
        allowed = np.empty_like(cost, dtype=bool)
        for i, o in enumerate(objects):
            for j, d in enumerate(found):
                far = float(np.linalg.norm(np.subtract(d.pose.position, last[o].position)))
                same = d.type_name == world.type_of(o)
                allowed[i, j] = same or far < (rules.track_distance if d.views > 1 else lone)
                cost[i, j] = min(far, STILL) + (0.0 if same else MISMATCH)
                cost[i, j] += 1e-3 * far - 1e-2 * d.score
        cost[~allowed] = FORBIDDEN
        for i, j in zip(*linear_sum_assignment(cost), strict=True):
            if allowed[i, j]:
                out[objects[i]] = found[j]
    return out
