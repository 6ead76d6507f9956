"""f_p's decoding, PnP and fusion on a rendered scene, with a stand-in network that outputs
the scene's true maps: what the estimator makes of perfect maps, and how the evaluation
scores it. (The trained network's quality is measured by `hsgplan eval-perception`.)"""

import math

import numpy as np
import torch

from hsgplan.domain.objects import type_of
from hsgplan.domain.world import OBJECT_TYPES
from hsgplan.perception.estimator import PoseEstimator
from hsgplan.perception.evaluate import rotation_error, score_scene, summary
from hsgplan.perception.keypoints import PinholeCamera, view_keypoints
from hsgplan.perception.maps import targets
from hsgplan.perception.model import STRIDE
from hsgplan.perception.synthetic import render_sample
from hsgplan.perception.train import MIN_VISIBLE
from hsgplan.scene_graph.geometry import Pose

TYPES = list(OBJECT_TYPES)


class _TrueMaps(torch.nn.Module):
    """Outputs the true maps of a sample's views, whatever the images."""

    stride = STRIDE

    def __init__(self, sample) -> None:
        super().__init__()
        views, height, width = sample.images.shape[:3]
        kinds = np.array([TYPES.index(type_of(o)) for o in sample.objects])
        maps = []
        for v in range(views):
            seen = sample.visible[v] >= MIN_VISIBLE
            pinhole = PinholeCamera.of(sample.cameras[v])
            named = np.stack(  # as this view names them
                [
                    view_keypoints(o, Pose(tuple(p[:3]), tuple(p[3:])), pinhole)
                    for o, p in zip(sample.objects, sample.poses.astype(float), strict=True)
                ]
            )
            maps.append(
                targets(
                    named[seen],
                    kinds[seen],
                    len(TYPES),
                    height // STRIDE,
                    width // STRIDE,
                )
            )
        self.beliefs = torch.from_numpy(np.stack([b for b, _ in maps]))
        self.fields = torch.from_numpy(np.stack([f for _, f in maps]))

    def forward(self, images):
        return [(self.beliefs, self.fields)]


def test_perfect_maps_give_the_scene_back_duplicates_and_all():
    sample = render_sample(0, 1)  # twelve objects, five alphabet soups among them
    assert sample is not None and len(sample.objects) == 12
    detections = PoseEstimator(_TrueMaps(sample)).detect(sample.images, sample.cameras)
    result = score_scene(sample, detections)
    seen = (sample.visible >= MIN_VISIBLE).any(axis=0)
    assert result.found >= seen.sum() - 1
    assert np.median(result.translation_cm) < 0.5 and np.median(result.rotation_deg) < 3
    report = summary([result])
    assert report["scenes"] == 1 and report["translation_cm_median"] < 0.5


def test_rotation_error_counts_a_cuboid_symmetry_as_no_error():
    upright = Pose.from_xyz_yaw(0.5, 0.0, 0.02, 0.3)
    turned = Pose.from_xyz_yaw(0.5, 0.0, 0.02, 0.3 + math.pi)
    assert rotation_error("butter", upright, turned) < 1e-4  # half a turn: the same cuboid
    assert (
        abs(rotation_error("butter", upright, Pose.from_xyz_yaw(0.5, 0, 0.02, 0.5)) - 11.46) < 0.1
    )
    assert rotation_error("cherries", upright, Pose.from_xyz_yaw(0.5, 0, 0.02, 2.0)) < 1e-4
