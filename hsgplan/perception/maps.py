"""Belief maps and affinity fields: made from labelled keypoints (the training targets) and
read back into keypoints per object instance (the network's output decoded), as DOPE does.

Maps live on the network's output grid, S input pixels per cell (the network's stride, 4 or
2); cell (i, j) covers input pixels [S j, S (j + 1)) across and its centre is at
S j + (S - 1) / 2 in OpenCV's pixel coordinates. A belief map holds, per (type, keypoint), a
Gaussian of `SIGMA` cells around every instance's keypoint (the maximum where two meet). An
affinity field holds, per corner (whatever the type), within `FIELD_RADIUS` cells of every
instance's corner, the vector from there to the instance's centroid, in cells; elsewhere zero,
and not trained.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from hsgplan.perception.keypoints import KEYPOINTS
from hsgplan.perception.model import CORNERS, STRIDE

SIGMA = 1.0  # cells
FIELD_RADIUS = 2.0  # cells
PEAK_THRESHOLD = 0.3
MIN_APART = 2.0  # cells between two peaks of one map
MAX_PEAKS = 16  # per map: more objects of one type than a scene holds
CENTROID = KEYPOINTS - 1
MAX_DISTANCE_PX = 12.0  # between where a corner's field points and its centroid


def to_cells(pixels: np.ndarray, stride: int = STRIDE) -> np.ndarray:
    return (pixels - (stride - 1) / 2) / stride


def to_pixels(cells: np.ndarray, stride: int = STRIDE) -> np.ndarray:
    return cells * stride + (stride - 1) / 2


@dataclass(frozen=True)
class Instance:
    """One object instance found in one image.

    Attributes:
        type_index: index into the kitchen's object types (f_p's classes).
        pixels: [9, 2] keypoints (8 corners, then the centroid), NaN for a corner not found.
        score: the centroid's belief.
    """

    type_index: int
    pixels: np.ndarray
    score: float


def targets(
    keypoints: np.ndarray,
    types: np.ndarray,
    types_count: int,
    height: int,
    width: int,
    stride: int = STRIDE,
) -> tuple[np.ndarray, np.ndarray]:
    """Training targets for one image.

    Args:
        keypoints: [M, 9, 2] pixel keypoints of the objects in sight.
        types: [M] their type indices.
        types_count: how many types the network knows.
        height, width: the output grid.
        stride: input pixels per output cell.

    Returns:
        beliefs [types * 9, height, width] and fields [8 * 2, height, width], float32.
    """
    beliefs = np.zeros((types_count * KEYPOINTS, height, width), dtype=np.float32)
    fields = np.zeros((CORNERS * 2, height, width), dtype=np.float32)
    ys, xs = np.mgrid[0:height, 0:width].astype(np.float32)
    for points, t in zip(keypoints, types, strict=True):
        cells = to_cells(points, stride)
        centroid = cells[CENTROID]
        for k, (x, y) in enumerate(cells):
            d2 = (xs - x) ** 2 + (ys - y) ** 2
            channel = beliefs[t * KEYPOINTS + k]
            np.maximum(channel, np.exp(-d2 / (2 * SIGMA**2)), out=channel)
            if k < CORNERS:
                near = d2 <= FIELD_RADIUS**2
                base = k * 2
                fields[base][near] = centroid[0] - xs[near]
                fields[base + 1][near] = centroid[1] - ys[near]
    return beliefs, fields


def peaks(
    belief: np.ndarray, threshold: float = PEAK_THRESHOLD
) -> list[tuple[float, float, float]]:
    """Local maxima of one map above `threshold`, strongest first (at most `MAX_PEAKS`), none
    within `MIN_APART` cells of a stronger one (a keypoint half-way between cells makes two
    equal maxima), each refined by a parabola through the log beliefs of its neighbours along
    x and along y (exact for a Gaussian): (x, y, belief) in cells."""
    (ys, xs), log = _cells(_maxima(belief[None], threshold))[0], _log_padded(belief[None])[0]
    return _refined(belief, ys, xs, log)


def _maxima(beliefs: np.ndarray, threshold: float) -> np.ndarray:
    """Where maps [C, H, W] peak above `threshold` (no neighbour higher), all maps at once:
    [C, H, W] bool. The neighbours' maximum is a 3 x 3 dilation of the maps as the channels of
    one image (outside the map counts as no neighbour)."""
    highest = np.concatenate(
        [_dilated(beliefs[c : c + MAX_CHANNELS]) for c in range(0, len(beliefs), MAX_CHANNELS)]
    )
    return (beliefs >= highest) & (beliefs > threshold)


MAX_CHANNELS = 128  # the most channels OpenCV takes in one image


def _dilated(maps: np.ndarray) -> np.ndarray:
    out = cv2.dilate(np.ascontiguousarray(maps.transpose(1, 2, 0)), np.ones((3, 3), np.uint8))
    return out.reshape(*out.shape[:2], -1).transpose(2, 0, 1)  # OpenCV drops a lone channel


def _log_padded(beliefs: np.ndarray) -> np.ndarray:
    """The log of maps [C, H, W], floored, with a border of the floor: [C, H + 2, W + 2]."""
    return np.log(np.maximum(np.pad(beliefs, ((0, 0), (1, 1), (1, 1)), constant_values=-1.0), 1e-6))


def _cells(maxima: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """Where each map of `maxima` [C, H, W] is set, as `np.nonzero` of each: (rows, columns)."""
    maps, ys, xs = np.nonzero(maxima)
    bounds = np.searchsorted(maps, np.arange(len(maxima) + 1))
    return [(ys[a:b], xs[a:b]) for a, b in zip(bounds[:-1], bounds[1:], strict=True)]


def _refined(
    belief: np.ndarray, ys: np.ndarray, xs: np.ndarray, log: np.ndarray
) -> list[tuple[float, float, float]]:
    """`peaks` of one map from the cells where it peaks (`_maxima`, `_cells`) and its
    `_log_padded`."""
    if not len(ys):
        return []
    order = np.argsort(-belief[ys, xs], kind="stable")[: 8 * MAX_PEAKS]
    out: list[tuple[float, float, float]] = []
    for y, x in zip(ys[order], xs[order], strict=True):
        if len(out) == MAX_PEAKS:
            break
        if any((px - x) ** 2 + (py - y) ** 2 < MIN_APART**2 for px, py, _ in out):
            continue
        centre = log[y + 1, x + 1]
        out.append(
            (
                x + _vertex(log[y + 1, x], centre, log[y + 1, x + 2]),
                y + _vertex(log[y, x + 1], centre, log[y + 2, x + 1]),
                float(belief[y, x]),
            )
        )
    return out


def _vertex(before: float, centre: float, after: float) -> float:
    """Where the parabola through three equally spaced values peaks, from the middle one."""
    curvature = before - 2 * centre + after
    if curvature >= 0:  # flat or not a maximum: stay on the cell
        return 0.0
    return float(min(max(0.5 * (before - after) / curvature, -0.5), 0.5))


def decode(beliefs: np.ndarray, fields: np.ndarray, stride: int = STRIDE) -> list[Instance]:
    """Instances from one image's maps: a centroid peak per instance, and for each corner the
    peak whose affinity vector points closest to that centroid (within `MAX_DISTANCE_PX`).

    Args:
        beliefs: [types * 9, H, W]; fields: [8 * 2, H, W]; stride: input pixels per cell.
    """
    max_distance = MAX_DISTANCE_PX / stride
    peaked = _cells(_maxima(beliefs, PEAK_THRESHOLD))  # every map at once: a look has dozens
    log = _log_padded(beliefs)
    found = []
    for t in range(beliefs.shape[0] // KEYPOINTS):
        centroid = t * KEYPOINTS + CENTROID
        centroids = _refined(beliefs[centroid], *peaked[centroid], log[centroid])
        if not centroids:
            continue
        xs, ys = np.array([c[0] for c in centroids]), np.array([c[1] for c in centroids])
        cells = np.full((len(centroids), KEYPOINTS, 2), np.nan)
        best = np.full((len(centroids), CORNERS), np.inf)
        for i, (x, y, _) in enumerate(centroids):
            cells[i, CENTROID] = (x, y)
        for k in range(CORNERS):
            base = k * 2
            m = t * KEYPOINTS + k
            for x, y, _ in _refined(beliefs[m], *peaked[m], log[m]):
                iy, ix = int(round(y)), int(round(x))
                target = np.array([x + fields[base, iy, ix], y + fields[base + 1, iy, ix]])
                d = np.hypot(target[0] - xs, target[1] - ys)
                i = int(np.argmin(d))
                if d[i] <= max_distance and d[i] < best[i, k]:
                    best[i, k], cells[i, k] = d[i], (x, y)
        for i, (_, _, score) in enumerate(centroids):
            found.append(Instance(t, to_pixels(cells[i], stride), score))
    return found
