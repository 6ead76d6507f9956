"""What drawing a start scene costs: `hsgplan bench start`.

An episode begins with a start scene drawn for its goal's objects (`sim.sampler`): an
arrangement drawn symbolically, posed, settled, and kept only if it reads back as drawn with
every object graspable; otherwise it is drawn again, up to `sampler.ATTEMPTS` times, and the
episode is left out of every rate as unsampled. On an evaluation's own goals and episode seeds
(`evaluation.protocol.episode_specs`), by size: how many draws a scene took, how long, and how
many could not be drawn. One core.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass

from hsgplan.domain.errors import UnsampledSceneError
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.scene_file import default_world
from hsgplan.evaluation.config import EvalConfig, world_of_file
from hsgplan.evaluation.protocol import episode_specs
from hsgplan.sim.env_types import reset_options
from hsgplan.sim.sampler import ATTEMPTS, REPAIRS, drawn_scene


@dataclass(frozen=True)
class StartTiming:
    """Start scenes of one size: draws and seconds per scene (an unsampled one counts its
    `ATTEMPTS` draws and its seconds)."""

    objects: int
    repairs: int  # a draw's, before it is given up
    scenes: int
    unsampled: int
    draws_median: float
    draws_max: int
    draws_total: int
    seconds_median: float

    def to_json(self) -> dict:
        return asdict(self)


def bench_start(
    sizes: Sequence[int],
    goals: int,
    seed: int,
    split: str | None = None,
    scene: str | None = None,
    on_scene: Callable[[], None] | None = None,
    repairs: int | None = None,
) -> list[StartTiming]:
    """Draw the start scene of every episode an `eval world` of these sizes, goals, seed,
    split and scene (a file) runs, each draw mended up to `repairs` times (None: the
    sampler's `REPAIRS`); a row per size."""
    repairs = REPAIRS if repairs is None else repairs
    config = EvalConfig("oracle", tuple(sizes), goals, seed, split=split, scene=scene)
    rows: dict[int, list[tuple[int, float, bool]]] = {}
    for spec in episode_specs(config):
        world = default_world() if spec.scene is None else world_of_file(spec.scene)
        options = reset_options(
            {"goal": parse_goal(spec.goal, world=world)}, None, spec.seed, world
        )
        start = time.perf_counter()
        try:
            scene, _, draws = drawn_scene(
                options.objects(),
                spec.seed,
                options.p_elsewhere,
                visuals=False,
                world=world,
                repairs=repairs,
            )
            scene.close()
            drawn = True
        except UnsampledSceneError:
            draws, drawn = ATTEMPTS, False
        rows.setdefault(spec.size, []).append((draws, time.perf_counter() - start, drawn))
        if on_scene:
            on_scene()
    return [
        StartTiming(
            n,
            repairs,
            len(r),
            sum(not ok for _, _, ok in r),
            statistics.median(d for d, _, _ in r),
            max(d for d, _, _ in r),
            sum(d for d, _, _ in r),
            statistics.median(s for _, s, _ in r),
        )
        for n, r in sorted(rows.items())
    ]
