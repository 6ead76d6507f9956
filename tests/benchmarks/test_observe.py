"""`hsgplan bench observe` on two scenes: its rows, and rendering timed apart from the
observation."""

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
        # two scenes a row at most: a median is a mean, and a look is the sum of its parts
        assert r.look_median == pytest.approx(r.render_median + r.observation_median, abs=1e-6)
        assert r.look_p90 >= r.look_median


def test_the_loops_rendering_leaves_the_sample_as_it_was():
    import numpy as np

    from hsgplan.perception.synthetic import render_sample

    shown = []
    sample = render_sample(100, 1, KITCHEN, staged=shown.append)
    assert len(shown) == 1 and sample is not None
    again = render_sample(100, 1, KITCHEN)
    assert np.array_equal(sample.images, again.images)
    assert np.array_equal(sample.poses, again.poses)
