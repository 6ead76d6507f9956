"""The paper's regression loop (`paper_loop.py`) over networks replaced by hand-written stand-ins:
one path down from the goal, each subgoal drawn uniformly, taken where f_reach says so."""

from pathlib import Path

from hsgplan.domain.actions import Pick, Place
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.predicates import Literal, in_grasp, on
from hsgplan.paths import TASK_CHECKPOINT
from hsgplan.planning.regression.paper_loop import TRIES, PaperRegressionPlanner
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph

GOAL = parse_goal("On(cherries, shelf_a) & On(butter, shelf_b)", world=KITCHEN)
START = SymbolicSceneGraph.from_literals(
    ["cherries", "butter"],
    [on("cherries", "open_space"), on("butter", "open_space")],
    world=KITCHEN,
)


class StandIns(PaperRegressionPlanner):
    """f_reach: yes for the literals in `reach`; f_preimage: `preimage[literal]`."""

    def __init__(self, reach: set[Literal], preimage: dict[Literal, set[Literal]], seed=0):
        super().__init__(Path(TASK_CHECKPOINT), seed)
        self.yes, self.pre, self.asked = reach, preimage, []

    def reachable(self, state, lits):
        self.asked += lits
        return [lit in self.yes for lit in lits]

    def _preimages(self, state, nodes):
        return [frozenset(self.pre.get(n.lit, ())) for n in nodes]


def _preimage_of_places() -> dict[Literal, set[Literal]]:
    return {
        on("cherries", "shelf_a"): {in_grasp("cherries")},
        on("butter", "shelf_b"): {in_grasp("butter")},
    }


def test_it_regresses_until_f_reach_says_reachable_and_takes_that_action():
    planner = StandIns({in_grasp("cherries"), in_grasp("butter")}, _preimage_of_places())
    decision = planner.next_action(START, GOAL)
    assert decision.action in (Pick("cherries"), Pick("butter"))
    # the goal literal drawn first, then its preimage's: two questions to f_reach
    assert len(planner.asked) == 2 and planner.asked[1] == decision.subgoal


def test_the_subgoal_is_drawn_uniformly_by_the_seed():
    picks = set()
    for seed in range(12):
        planner = StandIns({in_grasp("cherries"), in_grasp("butter")}, _preimage_of_places(), seed)
        picks.add(planner.next_action(START, GOAL).action)
    assert picks == {Pick("cherries"), Pick("butter")}
    again = [
        StandIns({in_grasp("butter"), in_grasp("cherries")}, _preimage_of_places(), 3)
        .next_action(START, GOAL)
        .action
        for _ in range(2)
    ]
    assert again[0] == again[1]


def test_a_literal_whose_preimage_holds_is_not_taken_unless_f_reach_says_so():
    held = SymbolicSceneGraph.from_literals(
        ["cherries", "butter"], [in_grasp("cherries"), on("butter", "shelf_b")], world=KITCHEN
    )
    said_no = StandIns(set(), _preimage_of_places())
    decision = said_no.next_action(held, GOAL)
    assert decision.action is None and decision.note == "regression stuck"
    assert len(said_no.asked) == TRIES  # one path a try, each ending at once
    said_yes = StandIns({on("cherries", "shelf_a")}, _preimage_of_places())
    assert said_yes.next_action(held, GOAL).action == Place("cherries", "shelf_a")
