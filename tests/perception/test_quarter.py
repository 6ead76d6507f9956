"""A box's quarter turn told by its silhouette (`perception.quarter`), on rendered scenes with
the shipped colour network: detections at the true poses stay, a box turned a quarter is turned
back, and what is not checked is left alone."""

import math
from dataclasses import replace

import numpy as np
import pytest

from hsgplan.domain.kitchen import KITCHEN
from hsgplan.paths import PERCEPTION_CHECKPOINT
from hsgplan.perception.colour import FOLDER, load_colour
from hsgplan.perception.detection import Detection
from hsgplan.perception.keypoints import PinholeCamera
from hsgplan.perception.pnp import ViewKeypoints
from hsgplan.perception.quarter import _quarter, quarter_checked
from hsgplan.perception.synthetic import render_sample
from hsgplan.perception.train import MIN_VISIBLE
from hsgplan.perception.vocabulary import KITCHEN_VOCABULARY
from hsgplan.scene_graph.geometry import Pose, rotation_apart

SEEN_BY = 2  # views that see a box well, for it to be checked here


@pytest.fixture(scope="module")
def colour():
    return load_colour(PERCEPTION_CHECKPOINT / FOLDER)


def _detections(sample):
    """Each object of a rendered sample detected at its true pose by the views it is in sight
    in."""
    out = []
    for i, name in enumerate(sample.objects):
        p = sample.poses[i]
        pose = Pose(tuple(map(float, p[:3])), tuple(map(float, p[3:])))
        views = tuple(
            ViewKeypoints(PinholeCamera.of(c), sample.keypoints[v, i])
            for v, c in enumerate(sample.cameras)
            if sample.visible[v, i] >= MIN_VISIBLE
        )
        out.append(Detection(KITCHEN.type_of(name), pose, 1.0, len(views), 0.0, keypoints=views))
    return out


def _boxes(found):
    return [
        k
        for k, d in enumerate(found)
        if d.type_name in ("butter", "cream_cheese", "popcorn")
        and d.pose.tilt < 0.1
        and len(d.keypoints) >= SEEN_BY
    ]


@pytest.mark.parametrize("index", [1, 2, 3])
def test_true_poses_stay_and_a_box_turned_a_quarter_turns_back(colour, index):
    sample = render_sample(0, index)
    assert sample is not None
    found = _detections(sample)
    boxes = _boxes(found)
    if not boxes:
        pytest.skip("no upright box in sight of two views in this sample")
    types = KITCHEN_VOCABULARY.types
    checked = quarter_checked(colour, types, KITCHEN, sample.images, sample.cameras, found)
    assert [d.pose for d in checked] == [d.pose for d in found]
    k = boxes[0]
    wrong = [*found[:k], replace(found[k], pose=_quarter(found[k].pose)), *found[k + 1 :]]
    back = quarter_checked(colour, types, KITCHEN, sample.images, sample.cameras, wrong)
    assert rotation_apart(back[k].pose, found[k].pose, False) < 0.1  # degrees: turned back
    assert [d.pose for j, d in enumerate(back) if j != k] == [
        d.pose for j, d in enumerate(found) if j != k
    ]


def test_cans_tilted_boxes_and_boxes_no_view_found_are_not_checked(colour):
    sample = render_sample(0, 1)
    found = _detections(sample)
    turned = [replace(d, pose=_quarter(d.pose)) for d in found]
    unseen = [replace(d, keypoints=()) for d in turned]
    types = KITCHEN_VOCABULARY.types
    # no view found any: nothing is read, nothing turns
    kept = quarter_checked(colour, types, KITCHEN, sample.images, sample.cameras, unseen)
    assert [d.pose for d in kept] == [d.pose for d in unseen]
    tilted = Pose((0.5, 0.0, 0.05), (math.sin(0.3), 0.0, 0.0, math.cos(0.3)))
    lying = [replace(d, pose=tilted) if d.type_name == "popcorn" else d for d in found]
    kept = quarter_checked(colour, types, KITCHEN, sample.images, sample.cameras, lying)
    assert all(d.pose == tilted for d in kept if d.type_name == "popcorn") and all(
        np.allclose(a.pose.orientation, b.pose.orientation)
        for a, b in zip(kept, lying, strict=True)
        if KITCHEN.object_type(a.type_name).kind.value == "can"
    )
