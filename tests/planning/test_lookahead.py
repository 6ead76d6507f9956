"""The regression planner's look-ahead (`regression-ahead`): a subgoal whose chain leads to a
literal f_reach finds out of reach once the subgoal is imagined achieved, or whose chain makes
the pick of an object still to move unlikely, is passed over while another is found. f_reach is
replaced by a hand-written stand-in here, so that what is tested is the mechanism, not what the
shipped network learned."""

from hsgplan.domain.actions import Pick
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.predicates import Literal, Predicate, clear, in_grasp, on
from hsgplan.paths import TASK_CHECKPOINT
from hsgplan.planning.regression.lookahead import (
    AHEAD_REACH,
    PICK_REACH,
    chain_reachable,
    imagined,
    keeps_picks,
)
from hsgplan.planning.regression.planner import RegressionPlanner
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph

# shelf_a's top holds four objects, its capacity; butter waits on the open space
FULL = SymbolicSceneGraph.from_literals(
    ["cherries", "alphabet_soup", "tomato_soup", "popcorn", "butter"],
    [
        on("cherries", "shelf_a"),
        on("alphabet_soup", "shelf_a"),
        on("tomato_soup", "shelf_a"),
        on("popcorn", "shelf_a"),
        on("butter", "open_space"),
    ],
    world=KITCHEN,
)


def test_a_state_imagined_moves_one_object_and_derives_what_is_clear():
    start = SymbolicSceneGraph.from_literals(
        ["cherries", "butter"],
        [on("cherries", "open_space"), on("butter", "cherries")],
        world=KITCHEN,
    )
    after = imagined(start, in_grasp("butter"))
    assert after.location("butter") == in_grasp("butter")
    assert after.location("cherries") == start.location("cherries")
    assert after.holds(clear("cherries")) and not after.holds(clear("butter"))
    assert start.location("butter") == on("butter", "cherries")  # the state itself is kept


def test_a_literal_that_places_nothing_is_not_imagined():
    assert imagined(FULL, clear("cherries")) is None
    assert imagined(FULL, Literal(Predicate.ON, ("butter", "open_space"), False)) is None


def _recording(reachable, asked: list):
    """f_reach's stand-in from a rule: 1 where `reachable` says so, else 0; every question is
    kept in `asked` as (state, literals)."""

    def scores(state, lits):
        asked.append((state, lits))
        return [float(reachable(state, lit)) for lit in lits]

    return scores


def _reach_refusing_full_tops(asked: list):
    """f_reach's stand-in: a place is in reach when its object is held and the top it goes to
    holds fewer than four objects; a pick when the hand is empty; nothing else."""

    def reachable(state, lit) -> bool:
        if lit.predicate is Predicate.ON:
            return state.held() == lit.subject and len(state.resting_on(lit.args[1])) < 4
        return lit.predicate is Predicate.IN_GRASP and state.held() is None

    return _recording(reachable, asked)


def test_a_chain_is_checked_link_by_link_in_the_state_imagined_below_it():
    asked: list = []
    reach = _reach_refusing_full_tops(asked)
    # InGrasp(butter) <- On(butter, shelf_a): the top is full once butter is in the hand
    assert not chain_reachable(FULL, in_grasp("butter"), [on("butter", "shelf_a")], reach)
    state, lits = asked[-1]
    assert lits == [on("butter", "shelf_a")] and state.location("butter") == in_grasp("butter")
    # the same chain towards shelf_b, whose top is empty, stays reachable
    assert chain_reachable(FULL, in_grasp("butter"), [on("butter", "shelf_b")], reach)
    # each link is asked in the state with the ones below achieved: butter on shelf_b, then
    # stacked on cherries (a place onto an object is in reach while it is held: not here)
    up = [on("butter", "shelf_b"), on("butter", "cherries")]
    assert not chain_reachable(FULL, in_grasp("butter"), up, reach)
    assert asked[-1][0].location("butter") == on("butter", "shelf_b")
    assert 0.0 < AHEAD_REACH < 0.5


def test_the_look_ahead_empties_a_full_top_before_it_fills_it():
    # the goal moves cherries off shelf_a's full top and butter onto it: picking butter first
    # would leave it in the hand with nowhere to go
    goal = parse_goal("On(cherries, shelf_b) & On(butter, shelf_a)", world=KITCHEN)
    for seed in range(4):
        planner = RegressionPlanner(TASK_CHECKPOINT, seed=seed, look_ahead=True)
        planner.reach_scores = _reach_refusing_full_tops([])
        planner.reset(goal, seed)
        assert planner.next_action(FULL, goal).action == Pick("cherries"), seed


def test_without_anything_else_to_do_the_planner_takes_a_subgoal_it_doubts():
    # nothing can leave the full top: the place is tried, as without the look-ahead
    goal = parse_goal("On(butter, shelf_a)", world=KITCHEN)
    planner = RegressionPlanner(TASK_CHECKPOINT, look_ahead=True)
    planner.reach_scores = _reach_refusing_full_tops([])
    planner.reset(goal, 0)
    assert planner.next_action(FULL, goal).action == Pick("butter")


# butter lies on shelf_b's top, cherries on the open space
BESIDE = SymbolicSceneGraph.from_literals(
    ["cherries", "butter"],
    [on("cherries", "open_space"), on("butter", "shelf_b")],
    world=KITCHEN,
)


def _reach_trapping_butter(asked: list):
    """f_reach's stand-in: a pick is likely with the hand empty, unless it is butter's and a can
    shares butter's top (the hand would meet it); a place is likely while its object is held."""

    def reachable(state, lit) -> bool:
        if lit.predicate is Predicate.IN_GRASP:
            if state.held() is not None:
                return False
            where = state.location(lit.subject)
            beside = [] if where is None else state.resting_on(where.args[1])
            return lit.subject != "butter" or "cherries" not in beside
        return state.held() == lit.subject

    return _recording(reachable, asked)


def test_a_chain_that_makes_a_pending_pick_unlikely_is_refused():
    asked: list = []
    reach = _reach_trapping_butter(asked)
    to_b = [in_grasp("cherries"), on("cherries", "shelf_b")]
    assert not keeps_picks(BESIDE, to_b, ["butter"], reach)
    # the pick is asked before and after, with cherries imagined on butter's top
    before, after = asked[-2][0], asked[-1][0]
    assert asked[-1][1] == [in_grasp("butter")]
    assert before.location("cherries") == on("cherries", "open_space")
    assert after.location("cherries") == on("cherries", "shelf_b")
    assert keeps_picks(BESIDE, [in_grasp("cherries"), on("cherries", "shelf_a")], ["butter"], reach)
    # the objects the chain moves are not its pending ones, and nothing pending asks nothing
    n = len(asked)
    assert keeps_picks(BESIDE, to_b, ["cherries"], reach) and len(asked) == n
    assert 0.0 < PICK_REACH <= 0.5


def test_stacking_onto_a_base_that_still_has_to_move_is_refused():
    # butter goes onto cherries, which another goal literal still has to move: once butter is
    # on it, cherries cannot be taken up (a stand-in for f_reach that asks for a clear object)
    def reachable(state, lit) -> bool:
        if lit.predicate is Predicate.IN_GRASP:
            return state.held() is None and state.holds(clear(lit.subject))
        return state.held() == lit.subject

    reach = _recording(reachable, [])
    onto = [in_grasp("butter"), on("butter", "cherries")]
    assert not keeps_picks(BESIDE, onto, ["cherries"], reach)
    assert keeps_picks(BESIDE, onto, [], reach)


def test_a_pick_already_unlikely_vetoes_nothing():
    trapped = SymbolicSceneGraph.from_literals(
        ["cherries", "butter", "tomato_soup"],
        [on("cherries", "open_space"), on("butter", "shelf_b"), on("tomato_soup", "shelf_b")],
        world=KITCHEN,
    )

    def scores(state, lits):  # butter's pick is a long shot whatever happens
        return [0.2 if lit == in_grasp("butter") else 1.0 for lit in lits]

    chain = [in_grasp("cherries"), on("cherries", "shelf_b")]
    assert keeps_picks(trapped, chain, ["butter"], scores)


def test_looking_sideways_moves_a_flat_box_before_a_can_is_put_beside_it():
    # both literals are free; without looking sideways the uniform draw sometimes puts
    # cherries beside butter first, after which butter cannot be taken up
    goal = parse_goal("On(cherries, shelf_b) & On(butter, shelf_a)", world=KITCHEN)
    firsts = {}
    for sideways in (True, False):
        firsts[sideways] = set()
        for seed in range(8):
            planner = RegressionPlanner(
                TASK_CHECKPOINT, seed=seed, look_ahead=True, sideways=sideways
            )
            planner.reach_scores = _reach_trapping_butter([])
            planner.reset(goal, seed)
            firsts[sideways].add(planner.next_action(BESIDE, goal).action)
    assert firsts[True] == {Pick("butter")}
    assert Pick("cherries") in firsts[False]
