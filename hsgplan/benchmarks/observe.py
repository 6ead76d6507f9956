"""What one look through f_p costs: `hsgplan bench observe`.

Each scene (`perception.synthetic.render_sample`, the evaluation's kind of scene) is staged;
as soon as it stands, its fixed cameras render it as a look in the loop does (`Camera.capture`,
the simulation's cost: a real robot's cameras deliver the images). The observation is what the
agent's observer does with the images: the keypoint network on every view, PnP, fusion across
views, naming by colour and resting (`PoseEstimator.detect`), then the tracker's assignment of
detections to the objects it knows (`perception.observer.tracked`, the known poses being the
scene's, as after a first look). A look in the simulated loop is the rendering and the
observation. One core (one torch thread), as an evaluation worker runs; medians and the 90th
percentile over the scenes, by the number of objects in them.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from functools import partial
from pathlib import Path

import numpy as np
import torch

from hsgplan.domain.world import World
from hsgplan.perception.estimator import PoseEstimator
from hsgplan.perception.observer import tracked
from hsgplan.perception.synthetic import render_sample
from hsgplan.perception.vocabulary import VIEW_COUNT, Vocabulary
from hsgplan.scene_graph.geometry import Pose

# objects in a scene, grouped: what a row of the table covers
GROUPS = ((2, 4), (5, 8), (9, 12))


@dataclass(frozen=True)
class ObserveTiming:
    """Seconds per scene over the scenes of one group of sizes."""

    objects: str
    scenes: int
    render_median: float  # the fixed cameras' images, as the loop renders them
    detect_median: float
    track_median: float
    observation_median: float
    observation_p90: float
    look_median: float  # rendering and observation: a look in the simulated loop
    look_p90: float

    def to_json(self) -> dict:
        return asdict(self)


def bench_observe(
    checkpoint: Path,
    scenes: int,
    seed: int,
    world: World,
    views: int = VIEW_COUNT,
    on_scene: Callable[[], None] | None = None,
) -> list[ObserveTiming]:
    """Time f_p on the scenes `(seed, 0 .. scenes - 1)` that could be staged (in `world`); a
    row per group of sizes that holds any, then one over all of them."""
    torch.set_num_threads(1)
    estimator = PoseEstimator.load(checkpoint)
    rest = partial(estimator.rest, world) if estimator.settled else None
    times: list[tuple[int, float, float, float]] = []
    cameras = Vocabulary(world).views[:views]
    for index in range(scenes):
        rendering: list[float] = []

        def render(scene, rendering=rendering) -> None:
            start = time.perf_counter()
            np.stack([c.capture(scene.bc) for c in cameras])
            rendering.append(time.perf_counter() - start)

        sample = render_sample(seed, index, world, views=views, staged=render)
        if sample is not None:
            rendered = rendering[0]
            known = {
                o: Pose(tuple(map(float, p[:3])), tuple(map(float, p[3:])))
                for o, p in zip(sample.objects, sample.poses, strict=True)
            }
            start = time.perf_counter()
            detections = estimator.detect(sample.images, sample.cameras, world)
            detected = time.perf_counter() - start
            start = time.perf_counter()
            tracked(detections, known, world, rest)
            times.append((len(sample.objects), rendered, detected, time.perf_counter() - start))
        if on_scene:
            on_scene()
    groups = [(f"{lo}-{hi}", [t for t in times if lo <= t[0] <= hi]) for lo, hi in GROUPS]
    return [_row(name, rows) for name, rows in [*groups, ("all", times)] if rows]


def _row(name: str, rows: list[tuple[int, float, float, float]]) -> ObserveTiming:
    observation = [d + t for _, _, d, t in rows]
    look = [r + d + t for _, r, d, t in rows]
    return ObserveTiming(
        name,
        len(rows),
        statistics.median(r for _, r, _, _ in rows),
        statistics.median(d for _, _, d, _ in rows),
        statistics.median(t for _, _, _, t in rows),
        statistics.median(observation),
        float(np.percentile(observation, 90)),
        statistics.median(look),
        float(np.percentile(look, 90)),
    )
