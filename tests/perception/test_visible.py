"""Detections painted where they were found: an object on another hides the lower one's
centroid from a camera above, not the lower one's side; and a detection is named by the colour
of what it keeps in sight, not of what hides its centroid."""

from dataclasses import replace

import numpy as np
import pytest
import torch

from hsgplan.domain.kitchen import KITCHEN
from hsgplan.perception import estimator as estimator_module
from hsgplan.perception.colour import MIN_REGION, features, pixel_vote
from hsgplan.perception.detection import Detection
from hsgplan.perception.estimator import PoseEstimator
from hsgplan.perception.keypoints import PinholeCamera, view_keypoints
from hsgplan.perception.pnp import ViewKeypoints
from hsgplan.perception.visible import painted, visible_masks
from hsgplan.perception.vocabulary import kitchen_vocabulary
from hsgplan.scene_graph.geometry import Pose

VIEWS = kitchen_vocabulary().views  # the shipped f_p's fixed cameras

TYPES = list(KITCHEN.object_types)
LOWER = Pose.from_xyz_yaw(0.45, 0.1, 0.012, 0.3)  # a thin box on the table
UPPER = Pose.from_xyz_yaw(0.45, 0.1, 0.036, 0.3)  # another on it


def _pixel(camera: PinholeCamera, pose: Pose) -> tuple[int, int]:
    u, v = np.round(camera.project(np.array([pose.position]))[0]).astype(int)
    return int(u), int(v)


def test_the_upper_box_hides_the_lower_ones_centroid_but_not_its_side():
    camera = PinholeCamera.of(VIEWS[0])
    label = painted(
        [KITCHEN.object_type("cream_cheese"), KITCHEN.object_type("butter")], [LOWER, UPPER], camera
    )
    u, v = _pixel(camera, LOWER)
    assert label[v, u] == 1  # the butter is what that pixel shows
    lower, upper = visible_masks(label, 2)
    assert lower.sum() >= MIN_REGION and upper.sum() > lower.sum()
    assert not (lower & upper).any()
    alone = painted([KITCHEN.object_type("cream_cheese")], [LOWER], camera)
    assert alone[v, u] == 0


class _NearestColour(torch.nn.Module):
    """Type logits: how near the chromaticity is to each type's own colour."""

    objects = len(TYPES)  # no background class

    def forward(self, x):
        rgb = torch.tensor([KITCHEN.object_types[t].color[:3] for t in TYPES])
        chroma = rgb / rgb.sum(dim=1, keepdim=True)
        return -100 * torch.cdist(x[:, :3], chroma)


def _detection(name: str, pose: Pose) -> Detection:
    seen = tuple(
        ViewKeypoints(
            PinholeCamera.of(c),
            view_keypoints(KITCHEN.object_type(name), pose, PinholeCamera.of(c)),
        )
        for c in VIEWS
    )
    return Detection(name, pose, 1.0, len(VIEWS), 0.0, (), 0.5, seen)


def _painted_images(types: list[str], poses: list[Pose]) -> np.ndarray:
    """The views with each painted pixel in its object's colour, the rest grey: [V, H, W, 3]."""
    images = []
    for camera in VIEWS:
        label = painted([KITCHEN.object_type(x) for x in types], poses, PinholeCamera.of(camera))
        image = np.full((camera.height, camera.width, 3), 128, dtype=np.uint8)
        for i, t in enumerate(types):
            image[label == i] = np.array(KITCHEN.object_types[t].color[:3]) * 255
        images.append(image)
    return np.stack(images)


def test_a_box_under_another_is_named_by_the_colour_of_its_side_in_sight():
    types, poses = ["cream_cheese", "butter"], [LOWER, UPPER]
    images = _painted_images(types, poses)
    estimator = PoseEstimator(torch.nn.Identity(), colour=_NearestColour())
    # both named butter, as the colour at the lower one's centroid says
    found = [_detection("butter", LOWER), _detection("butter", UPPER)]
    named = estimator._retyped(KITCHEN, images, VIEWS, found)
    assert [d.type_name for d in named] == types
    assert np.allclose(named[0].pose.position, LOWER.position, atol=0.005)


def test_a_region_half_hidden_by_a_soup_is_named_by_its_own_pixels_not_their_mean():
    soup, cheese = (
        KITCHEN.object_types["tomato_soup"].color[:3],
        KITCHEN.object_types["cream_cheese"].color[:3],
    )
    image = np.zeros((4, 10, 3), dtype=np.uint8)
    image[:, :5] = np.array(soup) * 255
    image[:, 5:] = np.array(cheese) * 255
    mask = np.ones((4, 10), dtype=bool)
    boxes = torch.tensor(
        [KITCHEN.object_types[t].kind is KITCHEN.object_types["butter"].kind for t in TYPES]
    )
    colour = _NearestColour()
    mean = colour(torch.from_numpy(features(image, np.array([5, 2]))[None]))[0]
    assert TYPES[int(torch.where(boxes, mean, -torch.inf).argmax())] == "butter"  # the mixture
    vote = pixel_vote(colour, image, mask, boxes)
    assert vote is not None and TYPES[int(vote.argmax())] == "cream_cheese"
    assert pixel_vote(colour, image, mask & (np.arange(10) < 5), boxes) is None  # no box pixels
    assert pixel_vote(colour, image[:1, :6], mask[:1, :6], boxes) is None  # too few pixels


def _blob(name: str, z: float, at: Pose = LOWER) -> Detection:
    """A detection where several views' rays meet at (`at`'s x, y, z), at its yaw."""
    centre = np.array([*at.position[:2], z])
    rays = tuple(
        (np.array(c.eye), (centre - c.eye) / np.linalg.norm(centre - c.eye)) for c in VIEWS
    )
    return replace(_detection(name, Pose(tuple(centre), at.orientation)), rays=rays)


def test_two_thin_boxes_seen_as_one_are_split_and_each_named_by_its_colour():
    types = ["cream_cheese", "butter"]
    images = _painted_images(types, [LOWER, UPPER])
    estimator = PoseEstimator(torch.nn.Identity(), colour=_NearestColour())
    height = KITCHEN.object_types["butter"].size[2]
    blob = _blob("butter", height)  # half-way up the stack: a box's height over the table
    split = estimator._unstacked(KITCHEN, images, VIEWS, [blob])
    assert [d.type_name for d in split] == types and all(d.stacked for d in split)
    assert [d.pose.position[2] for d in split] == pytest.approx([height / 2, 3 * height / 2])
    # a lone box's height, a popcorn, or a box with something found under it: no stack
    alone = _blob("butter", height / 2)
    assert estimator._unstacked(KITCHEN, images, VIEWS, [alone]) == [alone]
    tall = _blob("popcorn", height)
    assert estimator._unstacked(KITCHEN, images, VIEWS, [tall]) == [tall]
    under = _blob("cream_cheese", height / 2)
    assert estimator._unstacked(KITCHEN, images, VIEWS, [under, blob]) == [under, blob]


def test_a_thin_box_carrying_what_rests_on_one_box_is_not_split():
    images = _painted_images(["butter"], [LOWER])
    estimator = PoseEstimator(torch.nn.Identity(), colour=_NearestColour())
    height = KITCHEN.object_types["butter"].size[2]
    can = KITCHEN.object_types["tomato_soup"].size[2]
    blob = _blob("butter", height)  # found a box's height up, as two stacked would be
    on_one = _blob("tomato_soup", height + can / 2)
    assert estimator._unstacked(KITCHEN, images, VIEWS, [blob, on_one]) == [blob, on_one]
    on_two = _blob("tomato_soup", 2 * height + can / 2)
    split = estimator._unstacked(KITCHEN, images, VIEWS, [blob, on_two])
    assert sum(d.stacked for d in split) == 2 and on_two in split


class _WithBackground(_NearestColour):
    """`_NearestColour`, and a last class, the background, for grey."""

    def forward(self, x):
        grey = -100 * torch.cdist(x[:, :3], torch.full((1, 3), 1 / 3))
        return torch.cat([super().forward(x), grey], dim=1)


def test_pixels_named_background_are_no_votes():
    grey, cheese = (0.5, 0.5, 0.5), KITCHEN.object_types["cream_cheese"].color[:3]
    image = np.zeros((4, 10, 3), dtype=np.uint8)
    image[:, :8] = np.array(grey) * 255  # mostly table: the mean would be no box's
    image[:, 8:] = np.array(cheese) * 255
    mask = np.ones((4, 10), dtype=bool)
    boxes = torch.tensor(
        [KITCHEN.object_types[t].kind is KITCHEN.object_types["butter"].kind for t in TYPES]
    )
    vote = pixel_vote(_WithBackground(), image, mask, boxes)
    assert vote is not None and vote.shape == (len(TYPES),)
    assert TYPES[int(vote.argmax())] == "cream_cheese" and float(vote.sum()) == pytest.approx(1)
    assert pixel_vote(_WithBackground(), image, mask & (np.arange(10) < 8), boxes) is None


def test_pixels_near_another_objects_are_left_out_of_a_vote():
    kept = 0
    for view in VIEWS:
        label = painted(
            [KITCHEN.object_type("cream_cheese"), KITCHEN.object_type("butter")],
            [LOWER, UPPER],
            PinholeCamera.of(view),
        )
        lower, upper = visible_masks(label, 2)
        apart_lower, apart_upper = visible_masks(label, 2, apart=2)
        assert (apart_lower <= lower).all() and (apart_upper <= upper).all()
        near = np.argwhere(apart_lower)
        kept += len(near)
        if len(near):
            butter = np.argwhere(label == 1)
            gaps = np.abs(near[:, None] - butter[None]).max(axis=2)  # a 5 x 5 square around
            assert gaps.min() > 2
    assert kept >= MIN_REGION  # the lower box's side keeps pixels in some view


def test_a_stack_askew_is_split_and_each_box_named_by_its_own_pixels():
    askew = Pose.from_xyz_yaw(*UPPER.position, 0.3 + 0.5)  # turned against the lower box
    types = ["cream_cheese", "butter"]
    images = _painted_images(types, [LOWER, askew])
    estimator = PoseEstimator(torch.nn.Identity(), colour=_NearestColour())
    blob = _blob("butter", KITCHEN.object_types["butter"].size[2])  # at the lower one's yaw
    split = estimator._unstacked(KITCHEN, images, VIEWS, [blob])
    assert [d.type_name for d in split] == types


def test_a_detection_under_the_surface_a_stack_stands_on_does_not_keep_it_one_box():
    # two thin boxes on shelf A's top, seen as one blob; a can found inside the shelf under them
    top = KITCHEN.shelves["shelf_a"].top.z
    height = KITCHEN.object_types["butter"].size[2]
    x, y = 0.49, 0.38
    lower, upper = (Pose.from_xyz_yaw(x, y, top + k * height, 0.3) for k in (0.5, 1.5))
    images = _painted_images(["cream_cheese", "butter"], [lower, upper])
    estimator = PoseEstimator(torch.nn.Identity(), colour=_NearestColour())
    blob = _blob("butter", top + height, lower)
    inside = _detection("tomato_soup", Pose.from_xyz_yaw(x, y, 0.042, 0.0))
    split = estimator._unstacked(KITCHEN, images, VIEWS, [inside, blob])
    assert inside in split and sum(d.stacked for d in split) == 2
    on_top = _detection("butter", lower)  # the lower box, found over the shelf's top
    assert estimator._unstacked(KITCHEN, images, VIEWS, [on_top, blob]) == [on_top, blob]


def test_a_box_whose_pixels_all_lie_near_another_ones_edge_is_named_by_them(monkeypatch):
    types, poses = ["cream_cheese", "butter"], [LOWER, UPPER]
    monkeypatch.setattr(estimator_module, "APART_PX", 20)
    for view in VIEWS:  # none of the lower box's pixels lies that far from the butter's
        assert not visible_masks(
            painted([KITCHEN.object_type(x) for x in types], poses, PinholeCamera.of(view)), 2, 20
        )[0].any()
    images = _painted_images(types, poses)
    estimator = PoseEstimator(torch.nn.Identity(), colour=_NearestColour())
    found = [_detection("butter", LOWER), _detection("butter", UPPER)]  # as the centroids say
    named = estimator._retyped(KITCHEN, images, VIEWS, found)
    assert [d.type_name for d in named] == types


def test_what_is_painted_does_not_depend_on_the_order_the_cuboids_are_listed_in():
    # the faces are sorted far to near, whatever order the cuboids come in
    camera = PinholeCamera.of(VIEWS[0])
    butter, soup = KITCHEN.object_type("butter"), KITCHEN.object_type("tomato_soup")
    near = Pose.from_xyz_yaw(0.55, 0.05, soup.height / 2, 0.0)  # nearer the front camera
    far = Pose.from_xyz_yaw(0.40, 0.05, butter.height / 2, 0.4)
    one = painted([butter, soup], [far, near], camera)
    other = painted([soup, butter], [near, far], camera)
    swapped = np.where(other == 0, 1, np.where(other == 1, 0, other))
    assert np.array_equal(one, swapped)
    assert (one == 0).any() and (one == 1).any()
