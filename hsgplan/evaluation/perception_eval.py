"""`hsgplan eval perception`: f_p against the ground truth on fresh synthetic scenes, or on
scenes taken from inside the loop (`loop_scenes`).

Each scene (`perception.synthetic.render_sample`, another seed than training's) is seen by the
estimator; its detections are matched to the scene's objects type by type, nearest first
(within `MATCH_DISTANCE`). Per matched object: the translation error, and the rotation error
up to the cuboid's symmetries (a box looks the same turned half way about any of its axes; a
can about its axis, and upside down). A scene's symbolic scene graph from the estimated poses
(each matched detection named as the object it matched) must equal the one from the true
poses, every object found, for the scene to count as a symbolic match. Recall is the share of
objects found; precision the share of detections that match an object (a detection matching
none is a phantom, or an object found twice).

A scene that is no symbolic match is classed by what f_p misread (`MISREADS`, the first that
applies): an object not found where a detection of another type lies (`look_alike`), an object
of a stack not found (`stack_missed`), any other object not found (`unseen`: hidden, or never
found), or every object found and a relation read wrong: between stacked objects
(`stack_relation`), with a shelf (`shelf_relation`), or another (`other_relation`).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from hsgplan.domain.objects import EntityKind
from hsgplan.domain.world import Kind, World
from hsgplan.perception.detection import Detection
from hsgplan.perception.estimator import PoseEstimator
from hsgplan.perception.observer import away_from_hand
from hsgplan.perception.synthetic import ImageSample, render_sample
from hsgplan.perception.vocabulary import VIEW_COUNT
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.geometry import Pose, rotation_apart
from hsgplan.scene_graph.symbol_mapping import map_symbols
from hsgplan.sim.outcome import BELIEF_OFF, BELIEF_TURNED

MATCH_DISTANCE = 0.10  # m: a detection further than this from every object of its type matched none
# what a scene that is no symbolic match was misread by, in the order they are tried
MISREADS = (
    "look_alike",
    "stack_missed",
    "unseen",
    "stack_relation",
    "shelf_relation",
    "other_relation",
)


@dataclass(frozen=True)
class SceneResult:
    objects: int
    found: int
    translation_cm: tuple[float, ...]
    rotation_deg: tuple[float, ...]
    types: tuple[str, ...]  # of the matched objects, in the order of the errors
    symbolic_match: bool
    detections: int = 0  # everything f_p reported, matched or not
    misread: str | None = None  # one of MISREADS where the scene is no symbolic match


def rotation_error(obj: str, truth: Pose, estimate: Pose, world: World) -> float:
    """Degrees between two orientations of an object, up to its cuboid's symmetries."""
    return rotation_apart(truth, estimate, world.object_type(obj).kind is Kind.CAN)


def match(
    truth: dict[str, Pose], detections: list[Detection], world: World
) -> dict[str, Detection]:
    """Each object of the scene (its true pose) and the detection matched to it (type by
    type, nearest pair first)."""
    pairs = sorted(
        (np.linalg.norm(np.subtract(d.pose.position, truth[o].position)), o, k)
        for o in truth
        for k, d in enumerate(detections)
        if d.type_name == world.type_of(o)
    )
    matched: dict[str, Detection] = {}
    taken: set[int] = set()
    for distance, o, k in pairs:
        if distance < MATCH_DISTANCE and o not in matched and k not in taken:
            matched[o] = detections[k]
            taken.add(k)
    return matched


def score_scene(sample: ImageSample, detections: list[Detection], world: World) -> SceneResult:
    return score({o: _pose(sample, i) for i, o in enumerate(sample.objects)}, detections, world)


def score(truth: dict[str, Pose], detections: list[Detection], world: World) -> SceneResult:
    """A scene's detections against its objects' true poses (in a scene of `world`)."""
    matched = match(truth, detections, world)
    names = [o for o in truth if o in matched]
    translation = [
        100 * float(np.linalg.norm(np.subtract(matched[o].pose.position, truth[o].position)))
        for o in names
    ]
    rotation = [rotation_error(o, truth[o], matched[o].pose, world) for o in names]
    true_state = map_symbols(GeometricSceneGraph.from_poses(truth, world=world)).state
    seen_state = map_symbols(
        GeometricSceneGraph.from_poses({o: matched[o].pose for o in names}, world=world)
    ).state
    same = len(names) == len(truth) and true_state == seen_state
    return SceneResult(
        len(truth),
        len(names),
        tuple(translation),
        tuple(rotation),
        tuple(world.type_of(o) for o in names),
        same,
        len(detections),
        None if same else misread(truth, detections, matched, true_state, seen_state),
    )


def misread(truth, detections, matched, true_state, seen_state) -> str:
    """What a scene that is no symbolic match was misread by (`MISREADS`)."""
    missing = [o for o in truth if o not in matched]
    taken = {id(d) for d in matched.values()}
    spare = [d for d in detections if id(d) not in taken]
    for o in missing:
        near = (np.linalg.norm(np.subtract(d.pose.position, truth[o].position)) for d in spare)
        if any(distance < MATCH_DISTANCE for distance in near):
            return "look_alike"
    if any(true_state.resting_on(o) or _on_object(true_state, o) for o in missing):
        return "stack_missed"
    if missing:
        return "unseen"
    wrong = set(true_state.literals) ^ set(seen_state.literals)
    kind_of = true_state.world.kind_of
    targets = {kind_of(lit.args[-1]) for lit in wrong if lit.predicate.arity == 2}
    if EntityKind.OBJECT in targets:
        return "stack_relation"
    if EntityKind.SHELF in targets:
        return "shelf_relation"
    return "other_relation"


def _on_object(state, obj: str) -> bool:
    below = state.location(obj).args[-1]
    return state.world.kind_of(below) is EntityKind.OBJECT


def evaluate(
    estimator: PoseEstimator,
    scenes: int,
    seed: int,
    worlds: Sequence[World],
    on_scene: Callable[[], None] | None = None,
    views: int = VIEW_COUNT,
) -> list[SceneResult]:
    """The scenes `(seed, 0 .. scenes - 1)` that could be staged, each scored, seen from the
    first `views` fixed views; scene k staged in a scene of `worlds[k % len(worlds)]`."""
    out = []
    for index in range(scenes):
        world = worlds[index % len(worlds)]
        sample = render_sample(seed, index, world, views=views)
        if sample is not None:
            found = estimator.detect(sample.images, sample.cameras, world)
            out.append(score_scene(sample, found, world))
        if on_scene:
            on_scene()
    return out


def evaluate_loop(
    estimator: PoseEstimator,
    scenes: int,
    seed: int,
    worlds: Sequence[World],
    on_scene: Callable[[], None] | None = None,
    views: int = VIEW_COUNT,
) -> list[SceneResult]:
    """f_p on scenes from inside the loop (`loop_scenes`; scene k in `worlds[k % len(worlds)]`),
    seen from the first `views` fixed views as the rgb observer sees them."""
    from hsgplan.evaluation.loop_scenes import loop_scenes
    from hsgplan.perception.synthetic import first_views

    cameras = first_views(views, estimator.vocabulary.views)
    out = []
    for scene in loop_scenes(scenes, seed, cameras, worlds):
        detections = estimator.detect(scene.images, cameras, scene.world, scene.arm)
        # the robot knows where its hand is: what is there is not f_p's to find
        detections = away_from_hand(detections, scene.held)
        out.append(score(scene.truth, detections, scene.world))
        if on_scene:
            on_scene()
    return out


def summary(results: list[SceneResult]) -> dict:
    """Medians over matched objects, and the share of them off f_p's targets (more than
    `BELIEF_OFF` or `BELIEF_TURNED`), per type and overall; rates over scenes and objects."""
    rows = [
        (t, tc, rd)
        for r in results
        for t, tc, rd in zip(r.types, r.translation_cm, r.rotation_deg, strict=True)
    ]

    def medians(selected):
        return {
            "objects": len(selected),
            "translation_cm_median": float(np.median([x[1] for x in selected]))
            if selected
            else None,
            "rotation_deg_median": float(np.median([x[2] for x in selected])) if selected else None,
            # the tail a grasp meets: objects off f_p's targets for one pose
            "off_targets": (
                sum(x[1] > 100 * BELIEF_OFF or x[2] > BELIEF_TURNED for x in selected)
                / len(selected)
                if selected
                else None
            ),
        }

    objects = sum(r.objects for r in results)
    detections = sum(r.detections for r in results)
    found = sum(r.found for r in results)
    return {
        **medians(rows),
        "scenes": len(results),
        "found_rate": found / objects if objects else 0.0,
        # detections that match an object (each object is matched by one detection at most)
        "precision": found / detections if detections else 1.0,
        "unmatched_detections": detections - found,
        "symbolic_match_rate": (
            sum(r.symbolic_match for r in results) / len(results) if results else 0.0
        ),
        # scenes that are no symbolic match, by what was misread
        "misreads": dict(Counter(r.misread for r in results if r.misread).most_common()),
        "by_type": {
            t: medians([x for x in rows if x[0] == t]) for t in sorted({x[0] for x in rows})
        },
    }


def _pose(sample: ImageSample, i: int) -> Pose:
    p = sample.poses[i]
    return Pose(tuple(map(float, p[:3])), tuple(map(float, p[3:])))
