"""Train, tune and test: the goals, start scenes and scene layouts each may draw.

A split is data: a range of run seeds (the start scene of every episode derives from its run's
seed, `evaluation.seeds.episode_seed`), a share of the goal space, and a range of layout seeds
(`hsgplan scenes --seed`). Training collections draw from `train`, every rule, threshold and
hyperparameter is chosen on `tune`, and published numbers come from `test`.

The goal space of a size is cut by a hash of each goal's canonical text (`canonical`: its
literals sorted, look-alike instances named in the order that sorts first), so a goal belongs
to one split whoever draws it: a split's goals are the generator's, those of other shares
passed over. Where a size's goal space is too small to cut (`SHARED_SIZES`: 2 objects without
stacking hold 93 goals), every split draws from all of it and `hsgplan splits check` says how
many goals the test shares; (goal, start scene) pairs stay apart there too, by seed.
"""

from __future__ import annotations

import hashlib
import random
from dataclasses import dataclass

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.goals import Goal
from hsgplan.domain.predicates import literal_text
from hsgplan.domain.scene import World


@dataclass(frozen=True)
class Split:
    """One split: where its run seeds, goals and layouts come from.

    Attributes:
        seeds: its run seeds; the first is the one a `--split` run takes.
        goal_share: the hash buckets (of 100) whose goals it draws.
        layouts: its layout seeds (`hsgplan scenes --seed`).
    """

    name: str
    seeds: range
    goal_share: range
    layouts: range


BUCKETS = 100
TRAIN = Split("train", range(1_000_000, 2_000_000), range(30, BUCKETS), range(0, 900))
TUNE = Split("tune", range(900, 1000), range(20, 30), range(900, 1000))
TEST = Split("test", range(2_000_000, 2_001_000), range(0, 20), range(2_000_000, 2_001_000))
SPLITS: dict[str, Split] = {s.name: s for s in (TRAIN, TUNE, TEST)}
# sizes whose goal space every split shares: too few goals to cut (tested)
SHARED_SIZES = frozenset({2})
# draws a split may pass over per goal it keeps before the goal space is called too small
_MAX_DRAWS_PER_GOAL = 2000


def split_named(name: str) -> Split:
    if name not in SPLITS:
        raise InvalidInputError(f"--split '{name}': one of {', '.join(SPLITS)}")
    return SPLITS[name]


def canonical(goal: Goal) -> str:
    """The goal's text, the same for every reading of its look-alikes (`Goal.readings`): the
    least of the readings' sorted literal texts, made from the literals' parts (a goal of 12
    objects has hundreds of readings, and the test split's draws ask for thousands)."""
    parts = [(lit.predicate.value, lit.args, lit.positive) for lit in goal.literals]
    return min(
        " & ".join(
            sorted(literal_text(p, tuple(names.get(a, a) for a in args), s) for p, args, s in parts)
        )
        for names in goal.renamings()
    )


def bucket(goal: Goal) -> int:
    """The goal's hash bucket, 0..BUCKETS-1: the same on every machine and run."""
    digest = hashlib.sha256(canonical(goal).encode()).hexdigest()
    return int(digest[:8], 16) % BUCKETS


def split_of_goal(goal: Goal) -> str | None:
    """The split whose share the goal falls in; None where its size is shared."""
    if goal.size in SHARED_SIZES:
        return None
    b = bucket(goal)
    return next(s.name for s in SPLITS.values() if b in s.goal_share)


def check_seed(split: Split, seed: int) -> None:
    if seed not in split.seeds:
        raise InvalidInputError(
            f"--seed {seed} is not a {split.name} seed "
            f"({split.seeds.start}..{split.seeds.stop - 1})"
        )


def split_goals(
    split: Split | None, n: int, count: int, seed: int, stacking: bool = True, *, world: World
) -> list[Goal]:
    """`count` goals over n objects of the split's share (None: the whole space, as drawn
    before splits): the generator's draws from `seed`, those of other shares passed over. The
    first k goals are the same however many are drawn."""
    from hsgplan.symbolic.generator import random_goal, random_goals

    if split is None or n in SHARED_SIZES:
        return random_goals(n, count, seed, stacking=stacking, world=world)
    rng = random.Random(f"goals-{n}-{seed}")
    kept: list[Goal] = []
    for _ in range(max(count, 1) * _MAX_DRAWS_PER_GOAL):
        if len(kept) == count:
            return kept
        goal = random_goal(n, rng, stacking=stacking, world=world)
        if bucket(goal) in split.goal_share:
            kept.append(goal)
    if len(kept) == count:
        return kept
    raise InvalidInputError(
        f"the {split.name} split found {len(kept)} of {count} goals of {n} objects in "
        f"'{world.name}': its goal space is too small to cut"
    )
