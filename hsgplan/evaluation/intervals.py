"""95% intervals of a success rate over trainings and goals, whichever repeats ran them.

The interval is a two-way bootstrap (scipy's `bootstrap`, percentile method) of a table whose
rows are the trainings of one configuration and whose columns are the goals of one size, each
cell that training's mean over its episodes of that goal (repeats kept together). A resample
draws trainings and goals independently, with replacement, and takes the mean over the drawn
goals of each goal's mean over the drawn trainings: the interval says how far the rate would
move with other trainings of the same configuration and another draw of goals as the split
draws them. Each size is its own stratum (a table's cells are per size). With one training
only goals are drawn; fewer than two goals give no interval. The resampling is seeded, so a
summary is the same every time it is made.
"""

from __future__ import annotations

import warnings
from collections.abc import Hashable, Mapping, Sequence

import numpy as np
from scipy.stats import bootstrap

CONFIDENCE = 0.95
RESAMPLES = 2000
SEED = 0


def goal_interval(
    strata: Mapping[str, Sequence[float]] | Sequence[Sequence[float]],
) -> tuple[float, float] | None:
    """The 95% interval of the mean over goals of each goal's mean (`strata`: each goal's
    episodes, of one training); None for fewer than two goals."""
    groups = list(strata.values()) if isinstance(strata, Mapping) else list(strata)
    return training_goal_interval({(None, g): v for g, v in enumerate(groups)})


def training_goal_interval(
    cells: Mapping[tuple[Hashable, Hashable], Sequence[float]],
) -> tuple[float, float] | None:
    """The 95% interval of the mean over goals of each goal's mean over trainings (`cells`:
    `(training, goal)` → that training's episodes of that goal); None for fewer than two
    goals."""
    trainings = sorted({t for t, _ in cells}, key=repr)
    goals = sorted({g for (_, g), episodes in cells.items() if len(episodes)}, key=repr)
    if len(goals) < 2:
        return None
    table = np.full((len(trainings), len(goals)), np.nan)
    row = {t: i for i, t in enumerate(trainings)}
    column = {g: j for j, g in enumerate(goals)}
    for (t, g), episodes in cells.items():
        if len(episodes):
            table[row[t], column[g]] = float(np.mean(episodes))
    seen = table[~np.isnan(table)]
    if np.all(seen == seen[0]):  # nothing varies: the interval is the point
        return float(seen[0]), float(seen[0])
    rng = np.random.default_rng(SEED)
    if len(trainings) < 2:  # one training: goals are all there is to draw
        result = bootstrap(
            (np.nanmean(table, axis=0),),
            np.mean,
            n_resamples=RESAMPLES,
            confidence_level=CONFIDENCE,
            method="percentile",
            vectorized=True,
            rng=rng,
        )
    else:
        result = bootstrap(
            (np.arange(len(trainings)), np.arange(len(goals))),
            lambda t, g: _mean_of_means(table, t, g),
            paired=False,  # trainings and goals drawn independently of one another
            n_resamples=RESAMPLES,
            confidence_level=CONFIDENCE,
            method="percentile",
            vectorized=False,
            rng=rng,
        )
    ci = result.confidence_interval
    return float(ci.low), float(ci.high)


def _mean_of_means(table: np.ndarray, trainings: np.ndarray, goals: np.ndarray) -> float:
    drawn = table[np.ix_(trainings.astype(int), goals.astype(int))]
    with warnings.catch_warnings():  # a goal no drawn training ran is left out of the mean
        warnings.simplefilter("ignore", RuntimeWarning)
        return float(np.nanmean(np.nanmean(drawn, axis=0)))


def separate(a: Sequence[float] | None, b: Sequence[float] | None) -> bool:
    """Whether two intervals do not overlap: the only difference called a gain."""
    return a is not None and b is not None and (a[1] < b[0] or b[1] < a[0])
