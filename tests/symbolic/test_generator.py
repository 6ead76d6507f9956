import random
from collections import Counter

import pytest

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.feasibility import check_literals
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.predicates import Predicate
from hsgplan.domain.world import Kind
from hsgplan.symbolic.generator import random_goal, random_goals, random_objects, random_state


def test_same_seed_same_goals_and_other_seed_other_goals():
    assert random_goals(5, 20, seed=3, world=KITCHEN) == random_goals(5, 20, seed=3, world=KITCHEN)
    assert random_goals(5, 20, seed=3, world=KITCHEN) != random_goals(5, 20, seed=4, world=KITCHEN)


@pytest.mark.parametrize("n", range(2, 13))
def test_goals_name_exactly_n_objects_and_are_feasible(n):
    for goal in random_goals(n, 30, seed=0, world=KITCHEN):
        assert goal.size == n
        check_literals(goal.literals, world=KITCHEN)
        assert len(goal.literals) == n  # one placement literal per object


def test_small_goals_use_distinct_types_and_large_ones_all_six():
    rng = random.Random(0)
    for n in range(2, 7):
        types = [KITCHEN.split_instance(o)[0] for o in random_objects(n, rng, world=KITCHEN)]
        assert len(set(types)) == n
    for n in range(7, 13):
        types = [KITCHEN.split_instance(o)[0] for o in random_objects(n, rng, world=KITCHEN)]
        assert set(types) == set(KITCHEN.object_types) and len(types) == n


def test_every_goal_kind_occurs_and_only_cans_go_inside():
    kinds = Counter()
    for goal in random_goals(4, 200, seed=1, world=KITCHEN):
        for lit in goal.literals:
            if lit.predicate is Predicate.IN:
                assert KITCHEN.object_types[KITCHEN.split_instance(lit.subject)[0]].kind is Kind.CAN
                kinds["inside"] += 1
            elif lit.args[1] in ("shelf_a", "shelf_b"):
                kinds[lit.args[1]] += 1
            else:
                kinds["stack"] += 1
    assert set(kinds) == {"shelf_a", "shelf_b", "inside", "stack"}
    assert min(kinds.values()) > 50


def test_stacking_can_be_left_out():
    for goal in random_goals(3, 100, seed=2, stacking=False, world=KITCHEN):
        assert all(lit.args[-1] in ("shelf_a", "shelf_b") for lit in goal.literals)


def test_bad_sizes_and_counts_are_refused():
    with pytest.raises(InvalidInputError, match="between 2 and 12"):
        random_goal(13, random.Random(0), world=KITCHEN)
    with pytest.raises(InvalidInputError, match="between 2 and 12"):
        random_goal(1, random.Random(0), world=KITCHEN)
    with pytest.raises(InvalidInputError, match="negative"):
        random_goals(3, -1, seed=0, world=KITCHEN)


def test_random_states_are_consistent_and_sometimes_stacked():
    rng = random.Random(5)
    stacked = on_shelf = 0
    for _ in range(200):
        objs = random_objects(rng.randint(2, 12), rng, world=KITCHEN)
        s = random_state(objs, rng, world=KITCHEN)
        assert s.held() is None and s.objects == objs
        stacked += any(s.level(o) == 2 for o in objs)
        on_shelf += any(s.location(o).args[-1] in ("shelf_a", "shelf_b") for o in objs)
        assert not any(s.location(o).predicate is Predicate.IN for o in objs)
    assert stacked > 20 and on_shelf > 20
