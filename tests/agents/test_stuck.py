"""When the task planner finds nothing, an agent that checks its actions offers the goal's own
literals' actions to its checks (`stuck_goal_literals`); the offers come from the goal, the
observed state and the hand, on tiny hand-built states."""

from dataclasses import replace

from hsgplan.agents.stuck import goal_actions
from hsgplan.domain.actions import Pick, Place, Push
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.parameters import PickParams, PushParams
from hsgplan.domain.predicates import in_grasp, inside, on
from hsgplan.domain.recovery import ALL_RULES
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from tests.agents.test_hierarchical import SG, Model, Planner, checking_agent

STATE = SymbolicSceneGraph.from_literals(
    ["cherries", "butter", "tomato_soup"],
    [on("cherries", "shelf_b"), on("butter", "open_space"), on("tomato_soup", "prepush_a")],
    world=KITCHEN,
)
GOAL = parse_goal(
    "On(cherries, shelf_a) & On(butter, open_space) & In(tomato_soup, shelf_a)", world=KITCHEN
)


def test_each_unsatisfied_literal_gets_its_action_the_pick_first_where_not_held():
    offers = goal_actions(STATE, GOAL, held=None)
    assert [(o.action, o.following, o.subgoal) for o in offers] == [
        (Pick("cherries"), Place("cherries", "shelf_a"), in_grasp("cherries")),
        (Push("tomato_soup", "shelf_a"), None, inside("tomato_soup", "shelf_a")),
    ]  # butter's literal holds already


def test_an_object_to_push_is_put_on_the_prepush_region_first():
    state = SymbolicSceneGraph.from_literals(
        ["tomato_soup"], [on("tomato_soup", "open_space")], world=KITCHEN
    )
    goal = parse_goal("In(tomato_soup, shelf_a)", world=KITCHEN)
    offers = goal_actions(state, goal, held=None)
    assert [(o.action, o.following) for o in offers] == [
        (Pick("tomato_soup"), Place("tomato_soup", "prepush_a"))
    ]


def test_with_the_hand_full_only_the_held_objects_place_is_offered():
    held = SymbolicSceneGraph.from_literals(
        ["cherries", "butter", "tomato_soup"],
        [in_grasp("cherries"), on("butter", "open_space"), on("tomato_soup", "prepush_a")],
        world=KITCHEN,
    )
    offers = goal_actions(held, GOAL, held="cherries")
    assert [o.action for o in offers] == [Place("cherries", "shelf_a")]


def test_a_stuck_planner_is_given_the_first_goal_action_that_passes_the_checks():
    stuck = Planner([])  # finds nothing, ever
    model = Model(unplannable={PickParams("cherries")})
    d = checking_agent(stuck).decide(SG, STATE, GOAL, model)
    assert d.action == Push("tomato_soup", "shelf_a") and "found nothing" in d.note
    off = checking_agent(Planner([]), replace(ALL_RULES, stuck_goal_literals=False))
    assert off.decide(SG, STATE, GOAL, model).action is None


def test_when_no_goal_action_passes_the_episode_ends_as_the_planners_would():
    every = {PickParams("cherries"), PushParams("tomato_soup", 0, 0)}
    d = checking_agent(Planner([])).decide(SG, STATE, GOAL, Model(unplannable=every))
    assert d.action is None and d.params is None
