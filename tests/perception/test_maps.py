"""Belief maps and affinity fields made from keypoints decode back into those keypoints, one
instance each, duplicates of a type apart."""

import numpy as np
import pytest

from hsgplan.domain.kitchen import KITCHEN
from hsgplan.perception.keypoints import PinholeCamera, in_world
from hsgplan.perception.maps import (
    PEAK_THRESHOLD,
    _cells,
    _log_padded,
    _maxima,
    _refined,
    decode,
    peaks,
    targets,
)
from hsgplan.perception.model import STRIDE
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.render import Camera

CAMERA = Camera(320, 240, (1.15, 0.0, 1.0), (0.42, 0.0, 0.05), 46.0)


def _keypoints(obj: str, x: float, y: float, yaw: float) -> np.ndarray:
    pose = Pose.from_xyz_yaw(x, y, KITCHEN.object_type(obj).height / 2, yaw)
    return PinholeCamera.of(CAMERA).project(in_world(KITCHEN.object_type(obj), pose))


def test_maps_of_two_butters_and_a_can_decode_into_their_keypoints():
    types = list(KITCHEN.object_types)
    objects = [("butter", 0.40, -0.10, 0.3), ("butter", 0.55, 0.12, -1.0), ("cherries", 0.5, 0, 0)]
    keypoints = np.stack([_keypoints(o, x, y, yaw) for o, x, y, yaw in objects])
    kinds = np.array([types.index(o) for o, *_ in objects])
    h, w = CAMERA.height // STRIDE, CAMERA.width // STRIDE
    beliefs, fields = targets(keypoints, kinds, len(types), h, w)
    found = decode(beliefs, fields)
    assert sorted(f.type_index for f in found) == sorted(kinds.tolist())
    for points, kind in zip(keypoints, kinds, strict=True):
        same = [f for f in found if f.type_index == kind]
        match = min(same, key=lambda f: np.linalg.norm(f.pixels[8] - points[8]))
        seen = ~np.isnan(match.pixels).any(axis=1)
        assert seen.sum() >= 7  # corners on top of one another may share a peak
        assert np.abs(match.pixels[seen] - points[seen]).max() < 1.0  # pixels


def test_two_thin_boxes_stacked_are_two_peaks_at_stride_2_and_one_blob_at_stride_4():
    """Butter on cream cheese: their centroids are 2.4 cm apart, a few pixels in the view; a
    quarter-resolution grid holds one peak of them, a half-resolution grid two."""
    types = list(KITCHEN.object_types)
    low = _keypoints("cream_cheese", 0.45, 0.0, 0.2)
    high = low.copy()
    high[:, 1] -= 6.0  # pixels: the upper box, seen just above the lower one
    kinds = np.array([types.index("butter")] * 2)
    counts = {}
    for stride in (4, 2):
        h, w = CAMERA.height // stride, CAMERA.width // stride
        beliefs, fields = targets(np.stack([low, high]), kinds, len(types), h, w, stride)
        found = decode(beliefs, fields, stride)
        counts[stride] = len(found)
        if stride == 2:
            centroids = sorted(f.pixels[8][1] for f in found)
            assert np.allclose(centroids, sorted([low[8][1], high[8][1]]), atol=0.5)
    assert counts == {4: 1, 2: 2}


def test_a_looks_maps_peak_together_where_each_peaks_alone():
    rng = np.random.default_rng(5)
    beliefs = rng.random((6, 20, 30)).astype(np.float32) ** 4  # sparse, uneven peaks
    together, logs = _maxima(beliefs, PEAK_THRESHOLD), _log_padded(beliefs)
    for belief, maxima, (ys, xs), log in zip(
        beliefs, together, _cells(together), logs, strict=True
    ):
        assert np.array_equal(np.stack([ys, xs]), np.stack(np.nonzero(maxima)))
        assert _refined(belief, ys, xs, log) == peaks(belief)
    assert together.any() and not together.all()


@pytest.mark.parametrize("maps", [1, 54, 200])  # 200: more than OpenCV dilates at once
def test_maps_peak_where_no_neighbour_is_higher(maps):
    rng = np.random.default_rng(maps)
    beliefs = rng.random((maps, 12, 17)).astype(np.float32) ** 4
    h, w = beliefs.shape[1:]
    padded = np.pad(beliefs, ((0, 0), (1, 1), (1, 1)), constant_values=-1.0)
    highest = np.max(
        [
            padded[:, 1 + dy : 1 + dy + h, 1 + dx : 1 + dx + w]
            for dy in (-1, 0, 1)
            for dx in (-1, 0, 1)
        ],
        axis=0,
    )
    expected = (beliefs >= highest) & (beliefs > PEAK_THRESHOLD)
    assert expected.any()
    assert np.array_equal(_maxima(beliefs, PEAK_THRESHOLD), expected)
