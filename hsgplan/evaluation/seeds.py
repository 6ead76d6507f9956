"""Seeds that choose and seeds that report.

A rule, a threshold, an epoch or a hyperparameter is chosen on tuning seeds only; numbers are
reported on the others. Seeds 900 to 999 are tuning seeds of every evaluation command. The
perception evaluation also keeps, as tuning seeds, those its estimator's rules were chosen on
before the range was declared. A run on a tuning seed says so in its title and its summary.
"""

from __future__ import annotations

TUNING = range(900, 1000)
# `eval perception` (staged scenes and `--loop`): the seeds its rules were chosen on
PERCEPTION_TUNING = frozenset({1, 2, 3, 4, 5, 21, 31, 32, 43})
# the goals of training collections run in the loop (`collect visited`): seed S draws the goals
# of seed GOAL_SEEDS.start + S, apart from every seed an evaluation is run on
GOAL_SEEDS = range(1_000_000, 2_000_000)


def is_tuning(seed: int, perception: bool = False) -> bool:
    """Whether `seed` chooses rules (and so reports nothing) for an evaluation."""
    return seed in TUNING or (perception and seed in PERCEPTION_TUNING)


def marked(title: str, seed: int, perception: bool = False) -> str:
    """A table's title, marked where its seed is a tuning seed."""
    if is_tuning(seed, perception):
        return f"{title} (a tuning seed: for choosing rules, not a result)"
    return title


def episode_seed(seed: int, size: int, index: int, repeat: int = 0) -> int:
    """The seed of one episode of a run: its goal's index among those of its size, and its
    repeat."""
    return (seed * 1_000_003 + size * 10_007 + index + repeat * 7_919_111) % (2**31)
