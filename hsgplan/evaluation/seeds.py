"""Seeds that choose and seeds that report.

A rule, a threshold, an epoch or a hyperparameter is chosen on tuning seeds only; numbers are
reported on the test split (`evaluation.splits`). The tune split's seeds, 900 to 999, are
tuning seeds of every evaluation command. The perception evaluation also keeps, as tuning seeds,
those its estimator's rules were chosen on before the range was declared. A run says in its
title which it is: a test-split run names its split, a tuning run that it is for choosing, and
a run on a bare seed that it is exploration.
"""

from __future__ import annotations

from hsgplan.evaluation.splits import TEST, TRAIN, TUNE

TUNING = TUNE.seeds
# `eval perception` (staged scenes and `--loop`): the seeds its rules were chosen on
PERCEPTION_TUNING = frozenset({1, 2, 3, 4, 5, 21, 31, 32, 43})
# the goals of training collections run in the loop (`collect visited`): seed S draws the goals
# of seed GOAL_SEEDS.start + S, apart from every seed an evaluation is run on
GOAL_SEEDS = TRAIN.seeds


def is_tuning(seed: int, perception: bool = False) -> bool:
    """Whether `seed` chooses rules (and so reports nothing) for an evaluation."""
    return seed in TUNING or (perception and seed in PERCEPTION_TUNING)


def marked(title: str, seed: int, perception: bool = False, split: str | None = None) -> str:
    """A table's title, marked where its run is for choosing (the tune split, a tuning seed)
    or exploration (a bare seed outside the test split)."""
    if split == TEST.name:
        return title
    if split == TUNE.name or is_tuning(seed, perception):
        return f"{title} (a tuning seed: for choosing rules, not a result)"
    return f"{title} (exploration: a bare seed, not the test split)"


def seed_words(seed: int, split: str | None) -> str:
    """How a title names its run's seed: its split where it has one."""
    return f"{split} split (seed {seed})" if split else f"seed {seed}"


def episode_seed(seed: int, size: int, index: int, repeat: int = 0) -> int:
    """The seed of one episode of a run: its goal's index among those of its size, and its
    repeat."""
    return (seed * 1_000_003 + size * 10_007 + index + repeat * 7_919_111) % (2**31)
