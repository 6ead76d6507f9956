"""Copies of the demonstrations with added objects, and the varied states asked about."""

import random
from pathlib import Path

from hsgplan.data.demos import load_demos
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.predicates import Predicate
from hsgplan.planning.regression.augment import (
    Trajectory,
    covering_one,
    holding_one,
    relocating_one,
    trajectories,
    with_distractors,
)
from hsgplan.planning.regression.examples import regressed_subgoals
from hsgplan.symbolic.transition import applicable_actions, apply

DEMOS = Path(__file__).resolve().parents[2] / "data" / "demos" / "v1"


def _placements(state, objects):
    return {
        lit
        for lit in state.literals
        if lit.predicate is not Predicate.CLEAR and lit.subject in objects
    }


def test_added_objects_stay_put_and_the_demonstration_is_unchanged():
    demos = load_demos(DEMOS, world=KITCHEN)
    rng = random.Random(0)
    for demo in demos:
        base = Trajectory.of(demo)
        copy = with_distractors(base, 10, rng)
        assert len(copy.states[0].objects) <= 12 and copy.added
        demo_objects = set(base.states[0].objects)
        for before, after in zip(base.states, copy.states, strict=True):
            assert _placements(after, demo_objects) == _placements(before, demo_objects)
            assert _placements(after, copy.added) == _placements(copy.states[0], copy.added)
        # each step is still one legal action of the transition model
        for s, t in zip(copy.states, copy.states[1:], strict=False):
            assert t in {apply(s, a) for a in applicable_actions(s)}
        assert regressed_subgoals(copy) == regressed_subgoals(base)
        assert not {lit.subject for lit in copy.extra_goal} & demo_objects


def test_trajectories_are_seeded():
    demos = load_demos(DEMOS, world=KITCHEN)
    a, b = trajectories(demos, 2, seed=3), trajectories(demos, 2, seed=3)
    assert len(a) == 3 * len(demos) and a == b
    assert trajectories(demos, 2, seed=4) != a


def test_varied_states_hold_cover_or_move_only_what_they_say():
    demo = next(
        d for d in load_demos(DEMOS, world=KITCHEN) if d.task == "stack-butter-on-cherries-shelf_a"
    )
    rng = random.Random(1)
    copy = with_distractors(Trajectory.of(demo), 6, rng)
    s0 = copy.states[0]
    held = holding_one(copy, s0, rng)
    assert held.held() in copy.added
    covered = covering_one(copy, s0, rng)
    moved = [o for o in s0.objects if covered.location(o) != s0.location(o)]
    assert len(moved) == 1 and moved[0] in copy.added
    assert covered.location(moved[0]).args[1] in {"cherries", "butter"}
    relocated = relocating_one(copy, s0, rng)
    moved = [o for o in s0.objects if relocated.location(o) != s0.location(o)]
    assert len(moved) == 1 and moved[0] in {"cherries", "butter"}
    assert holding_one(copy, held, rng) is None  # one hand
