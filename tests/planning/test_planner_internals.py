"""Pieces of the regression planner that must agree with slower reference code exactly."""

import random

from hsgplan.domain.kitchen import KITCHEN
from hsgplan.planning.regression.encoding import Slots, touching
from hsgplan.planning.regression.planner import literal_key
from hsgplan.symbolic.generator import random_goal, random_state


def test_the_sort_key_is_the_literals_own_order():
    rng = random.Random(0)
    for _ in range(20):
        goal = random_goal(rng.randint(2, 8), rng, world=KITCHEN)
        state = random_state(goal.objects, rng, world=KITCHEN)
        lits = list(goal.literals | state.literals | {lit.negated() for lit in state.literals})
        rng.shuffle(lits)
        assert sorted(lits, key=literal_key) == sorted(lits)


def test_touching_marks_the_edges_at_a_literals_arguments():
    rng = random.Random(1)
    goal = random_goal(4, rng, world=KITCHEN)
    nodes = random_state(goal.objects, rng, world=KITCHEN).nodes
    lits = sorted(goal.literals)
    marked = touching(nodes, [lit.args for lit in lits])
    slots = Slots.of(nodes)
    n = len(nodes)
    for k, lit in enumerate(lits):
        expected = {
            i * n + j for i in range(n) for j in range(n) if {nodes[i], nodes[j]} & set(lit.args)
        }
        assert set(marked[k].nonzero()[0].tolist()) == expected
        assert marked[k][slots.slot(lit)[0]]
