"""95% intervals of a success rate over trainings, goals and repeats.

The rate's interval is a stratified bootstrap (scipy's `bootstrap`, percentile method), the
recipe of rliable (Agarwal et al., 2021): each goal is a stratum, and its episodes (one per
training and repeat) are resampled within it; the statistic is the mean over goals of each
goal's mean. A goal met once has nothing to resample: an interval needs every goal run at
least twice (two trainings, or two repeats). The resampling is seeded, so a summary is the
same every time it is made.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from scipy.stats import bootstrap

CONFIDENCE = 0.95
RESAMPLES = 2000
SEED = 0


def _mean_over_strata(*samples: np.ndarray, axis: int = -1) -> np.ndarray:
    return np.mean([np.mean(s, axis=axis) for s in samples], axis=0)


def stratified_interval(
    strata: Mapping[str, Sequence[float]] | Sequence[Sequence[float]],
) -> tuple[float, float] | None:
    """The 95% interval of the mean over strata of each stratum's mean; None where a stratum
    holds fewer than two values."""
    groups = list(strata.values()) if isinstance(strata, Mapping) else list(strata)
    if not groups or min(len(g) for g in groups) < 2:
        return None
    samples = tuple(np.asarray(g, dtype=float) for g in groups)
    if all(np.all(s == s[0]) for s in samples):  # nothing varies: the interval is the point
        point = float(_mean_over_strata(*samples))
        return point, point
    result = bootstrap(
        samples,
        _mean_over_strata,
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
