"""`hsgplan bench observe` on two scenes: its rows, and rendering kept out of the observation."""

import pytest

from hsgplan.benchmarks.observe import bench_observe
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.paths import PERCEPTION_CHECKPOINT, shipped


@pytest.mark.slow
def test_an_observation_is_timed_apart_from_rendering_by_group_of_sizes():
    seen = []
    rows = bench_observe(
        shipped(PERCEPTION_CHECKPOINT), 2, 100, KITCHEN, on_scene=lambda: seen.append(1)
    )
    assert len(seen) == 2
    assert rows[-1].objects == "all" and rows[-1].scenes == sum(r.scenes for r in rows[:-1])
    for r in rows:
        assert r.observation_median == pytest.approx(r.detect_median + r.track_median, abs=1e-3)
        assert r.observation_p90 >= r.observation_median > 0 and r.render_median > 0
