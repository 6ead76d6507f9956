"""Synthetic training images for f_p: random scenes from the fixed cameras, domain randomised,
with every object's ground-truth pose and projected cuboid keypoints.

A sample is drawn from `(seed, index)` alone: 2 to 12 objects (duplicates past six, named
`cherries_2`, ...), arranged as the scene sampler arranges start scenes (mostly the open space,
some on shelf tops or stacked) plus some cans inside the shelves, staged and settled under
physics (`sim.staging.stage`). Then the look is randomised, as DOPE's synthetic data is: the
light's direction, colour and strength, the table's and the shelves' colours, each camera moved
by up to `CAMERA_JITTER`, up to `DISTRACTORS` shapes of random colour on the floor beside the
table, and Gaussian pixel noise. The objects' own colours are left as they are: they are what
tells the types apart.
"""

from __future__ import annotations

import random
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.objects import draw_objects
from hsgplan.domain.predicates import inside, on
from hsgplan.domain.world import Kind, World
from hsgplan.perception.keypoints import KEYPOINTS, PinholeCamera, in_world
from hsgplan.perception.vocabulary import VIEW_COUNT, Vocabulary
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.sim.render import Camera
from hsgplan.sim.scene import Scene
from hsgplan.sim.staging import stage
from hsgplan.symbolic.generator import random_state

MAX_OBJECTS = 12
CAMERA_JITTER = 0.02  # m, on the eye and on the point looked at, per axis
DISTRACTORS = 3
P_INSIDE = 0.3  # a clear can on the open space goes into a shelf with this chance
# Each object leaves the open space (for a shelf top or another object) with this chance, as
# the scene sampler's starts do; a collection may ask for more, for more stacks to learn from.
P_ELSEWHERE = 0.5
MAX_NOISE = 6.0  # pixel noise standard deviation, at most (0..255 scale)
NEAR, FAR = 0.05, 4.0

# Views past these draw their jitter from a stream of their own, so that a sample rendered from
# the first three is the same with or without the others (`collect images --views 3` renders
# the collection the shipped network was first trained on, byte for byte).
ORIGINAL_VIEWS = 3


@dataclass(frozen=True)
class ImageSample:
    """One randomised scene from every view.

    Attributes:
        seed, index: what the sample was drawn from.
        objects: the scene's objects, canonical order: N names.
        poses: their poses, [N, 7] (position, quaternion xyzw).
        cameras: each view as rendered (jittered): V cameras.
        images: [V, H, W, 3] uint8.
        keypoints: each object's 9 cuboid keypoints in each view, [V, N, 9, 2] pixels.
        visible: each object's pixels in sight in each view, [V, N].
    """

    seed: int
    index: int
    objects: tuple[str, ...]
    poses: np.ndarray
    cameras: tuple[Camera, ...]
    images: np.ndarray
    keypoints: np.ndarray
    visible: np.ndarray


def draw_state(rng: random.Random, p_elsewhere: float, world: World) -> SymbolicSceneGraph:
    """A random arrangement of 2 to `MAX_OBJECTS` objects of `world`, some cans inside the
    shelves."""
    objects = draw_objects(rng.randint(2, MAX_OBJECTS), rng, world)
    state = random_state(objects, rng, p_elsewhere=p_elsewhere, world=world)
    if not world.interior_capacity:  # no shelf to put a can inside
        return state
    inside_count = dict.fromkeys(world.interior_capacity, 0)
    literals = []
    for o in state.objects:
        where = state.location(o)
        shelf = rng.choice(sorted(world.interior_capacity))
        if (
            world.object_type(o).kind is Kind.CAN
            and where == on(o, "open_space")
            and not state.resting_on(o)
            and inside_count[shelf] < world.interior_capacity[shelf]
            and rng.random() < P_INSIDE
        ):
            inside_count[shelf] += 1
            literals.append(inside(o, shelf))
        else:
            literals.append(where)
    return SymbolicSceneGraph.from_literals(objects, literals, world=world)


def first_views(count: int, views: tuple[Camera, ...]) -> tuple[Camera, ...]:
    """The first `count` fixed `views`; a count past them (or under one) is refused in a
    line."""
    if not 1 <= count <= len(views):
        raise InvalidInputError(f"views {count}: there are 1 to {len(views)} fixed views")
    return views[:count]


def render_sample(
    seed: int,
    index: int,
    world: World,
    p_elsewhere: float = P_ELSEWHERE,
    views: int = VIEW_COUNT,
    staged: Callable[[Scene], None] | None = None,
) -> ImageSample | None:
    """The sample `(seed, index)` staged in a scene of `world`, from the first `views` of its
    fixed views; None when its arrangement could not be staged. `staged` is shown the scene
    as soon as it stands (a benchmark times the loop's own rendering there); it draws nothing
    from the sample's random streams."""
    every = Vocabulary(world).views
    first_views(views, every)
    rng = random.Random(f"images-{seed}-{index}")
    state = draw_state(rng, p_elsewhere, world)
    with Scene(state.objects, seed=rng.getrandbits(32), world=world) as scene:
        if not stage(scene, state, rng):
            return None
        if staged is not None:
            staged(scene)
        _randomise_fixtures(scene, rng)
        for _ in range(rng.randint(0, DISTRACTORS)):
            _add_distractor(scene, rng)
        # the first three's jitter is always drawn, so fewer views change nothing else
        cameras = tuple(_jittered(c, rng) for c in every[:ORIGINAL_VIEWS])[:views]
        light = _light(rng)
        cameras += tuple(
            _jittered(every[k], random.Random(f"images-{seed}-{index}-view-{k}"))
            for k in range(ORIGINAL_VIEWS, views)
        )
        objects = scene.objects
        poses = [scene.pose(o) for o in objects]
        images, keypoints, visible = [], [], []
        for camera in cameras:
            image, seg = _render(scene, camera, light)
            noise = rng.uniform(0.0, MAX_NOISE)
            noisy = image + np.random.default_rng(rng.getrandbits(32)).normal(0, noise, image.shape)
            images.append(np.clip(noisy, 0, 255).astype(np.uint8))
            pinhole = PinholeCamera.of(camera)
            points = zip(objects, poses, strict=True)
            keypoints.append(
                [pinhole.project(in_world(world.object_type(o), p)) for o, p in points]
            )
            visible.append([int((seg == scene.bodies[o]).sum()) for o in objects])
    return ImageSample(
        seed,
        index,
        objects,
        np.array([[*p.position, *p.orientation] for p in poses], dtype=np.float32),
        cameras,
        np.stack(images),
        np.asarray(keypoints, dtype=np.float32).reshape(len(cameras), len(objects), KEYPOINTS, 2),
        np.asarray(visible, dtype=np.int32),
    )


def _jittered(camera: Camera, rng: random.Random) -> Camera:
    def moved(p):
        return tuple(v + rng.uniform(-CAMERA_JITTER, CAMERA_JITTER) for v in p)

    return replace(camera, eye=moved(camera.eye), target=moved(camera.target))


def _light(rng: random.Random) -> dict:
    tint = [rng.uniform(0.8, 1.0) for _ in range(3)]
    return {
        "lightDirection": (rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(0.4, 1.5)),
        "lightColor": tint,
        "lightAmbientCoeff": rng.uniform(0.3, 0.8),
        "lightDiffuseCoeff": rng.uniform(0.3, 0.8),
        "lightSpecularCoeff": rng.uniform(0.0, 0.3),
        "shadow": rng.random() < 0.5,
    }


def _randomise_fixtures(scene: Scene, rng: random.Random) -> None:
    def color():
        return (*(rng.uniform(0.2, 0.95) for _ in range(3)), 1.0)

    scene.bc.changeVisualShape(scene.arena.table, -1, rgbaColor=color())
    for parts in scene.arena.shelves.values():
        shelf_color = color()
        for part in parts:
            scene.bc.changeVisualShape(part, -1, rgbaColor=shelf_color)


def _add_distractor(scene: Scene, rng: random.Random) -> None:
    """A shape of random size and colour on the floor beyond the table's far edge or sides:
    in the picture, never among the objects."""
    bc = scene.bc
    size = rng.uniform(0.02, 0.06)
    color = (*(rng.uniform(0, 1) for _ in range(3)), 1.0)
    shape = rng.choice((bc.GEOM_BOX, bc.GEOM_SPHERE, bc.GEOM_CYLINDER))
    if shape == bc.GEOM_BOX:
        visual = bc.createVisualShape(shape, halfExtents=(size, size, size), rgbaColor=color)
    elif shape == bc.GEOM_SPHERE:
        visual = bc.createVisualShape(shape, radius=size, rgbaColor=color)
    else:
        visual = bc.createVisualShape(shape, radius=size, length=2 * size, rgbaColor=color)
    beyond = (0.95, rng.uniform(-0.5, 0.5))
    beside = (rng.uniform(0.2, 0.9), rng.choice((-0.95, 0.95)))
    bc.createMultiBody(0, -1, visual, basePosition=(*rng.choice((beyond, beside)), size))


def _render(scene: Scene, camera: Camera, light: dict) -> tuple[np.ndarray, np.ndarray]:
    """RGB [H, W, 3] float and the segmentation (body ids) [H, W] of one view."""
    bc = scene.bc
    view = bc.computeViewMatrix(camera.eye, camera.target, (0, 0, 1))
    proj = bc.computeProjectionMatrixFOV(camera.fov, camera.width / camera.height, NEAR, FAR)
    _, _, rgba, _, seg = bc.getCameraImage(
        camera.width, camera.height, view, proj, renderer=bc.ER_TINY_RENDERER, **light
    )
    shape = (camera.height, camera.width)
    rgb = np.asarray(rgba, dtype=np.float64).reshape(*shape, 4)[:, :, :3]
    return rgb, np.asarray(seg).reshape(shape)
