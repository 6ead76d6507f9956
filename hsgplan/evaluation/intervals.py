"""95% intervals of a success rate over goals, whichever trainings and repeats ran them.

The interval is a bootstrap over goals (scipy's `bootstrap`, percentile method): a goal is the
unit drawn, its episodes under every training and repeat kept together as its mean, so the
interval says how far the rate would move with another draw of goals as the split draws them.
How far it moves with another training is each training's own rate, which the summaries keep
beside it (`success_by_training`). Fewer than two goals give no interval. The resampling is
seeded, so a summary is the same every time it is made.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from scipy.stats import bootstrap

CONFIDENCE = 0.95
RESAMPLES = 2000
SEED = 0


def goal_interval(
    strata: Mapping[str, Sequence[float]] | Sequence[Sequence[float]],
) -> tuple[float, float] | None:
    """The 95% interval of the mean over goals of each goal's mean (`strata`: each goal's
    episodes); None for fewer than two goals."""
    groups = list(strata.values()) if isinstance(strata, Mapping) else list(strata)
    means = np.array([np.mean(g) for g in groups if len(g)], dtype=float)
    if len(means) < 2:
        return None
    if np.all(means == means[0]):  # nothing varies: the interval is the point
        return float(means[0]), float(means[0])
    result = bootstrap(
        (means,),
        np.mean,
        n_resamples=RESAMPLES,
        confidence_level=CONFIDENCE,
        method="percentile",
        vectorized=True,
        rng=np.random.default_rng(SEED),
    )
    ci = result.confidence_interval
    return float(ci.low), float(ci.high)


def separate(a: Sequence[float] | None, b: Sequence[float] | None) -> bool:
    """Whether two intervals do not overlap: the only difference called a gain."""
    return a is not None and b is not None and (a[1] < b[0] or b[1] < a[0])
