"""Clearing the way: when every action offered fails its check, the agent moves neighbours
aside in its model first, then for real, and takes the blocked action up again. A tiny world
of poses stands for the scene: a pick of the box plans only with nothing within 15 cm of it."""

from __future__ import annotations

import math
from contextlib import contextmanager
from dataclasses import dataclass, field

from hsgplan.agents.clearing import CLEARINGS, find_clearing, neighbours
from hsgplan.agents.hierarchical import HierarchicalAgent
from hsgplan.domain.actions import Pick, Place
from hsgplan.domain.goals import Goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.parameters import PickParams, PlaceParams
from hsgplan.domain.predicates import in_grasp, on
from hsgplan.domain.scene import OPEN_SPACE
from hsgplan.planning.base import TaskDecision
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.geometry import Pose
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.sim.outcome import Outcome, Status

BOX = "butter"
ROOM = 0.15  # m: a pick of BOX plans with no other object's centre this close


@dataclass
class Tiny:
    """Poses on the table (x, y), what rests on what, and the hand's object."""

    xy: dict[str, tuple[float, float]]
    under: dict[str, str] = field(default_factory=dict)  # object -> the object it rests on
    held: str | None = None
    spots: int = 0  # places made on the open space, each at a new spot far off

    def copy(self) -> Tiny:
        return Tiny(dict(self.xy), dict(self.under), self.held, self.spots)

    def sg(self) -> GeometricSceneGraph:
        poses = {n: Pose((x, y, 0.05), (0.0, 0.0, 0.0, 1.0)) for n, (x, y) in self.xy.items()}
        return GeometricSceneGraph.from_poses(poses, self.held, world=KITCHEN)

    def state(self) -> SymbolicSceneGraph:
        lits = [
            in_grasp(o) if o == self.held else on(o, self.under.get(o, OPEN_SPACE)) for o in self.xy
        ]
        return SymbolicSceneGraph.from_literals(self.xy, lits, limits=False, world=KITCHEN)

    def plans(self, params) -> bool:
        if isinstance(params, PickParams):
            free = self.held is None and params.obj not in self.under.values()
            if params.obj != BOX:
                return free
            bx, by = self.xy[BOX]
            return free and all(
                math.hypot(x - bx, y - by) >= ROOM for o, (x, y) in self.xy.items() if o != BOX
            )
        return self.held == params.obj

    def run(self, params) -> Outcome:
        if not self.plans(params):
            return Outcome(Status.NO_IK, "", 0.0)
        if isinstance(params, PickParams):
            self.held = params.obj
            self.under.pop(params.obj, None)
        else:
            self.xy[params.obj] = (-0.5, 0.3 * self.spots)
            self.held, self.spots = None, self.spots + 1
        return Outcome(Status.SUCCESS, "", 0.0)


class Model:
    """The robot's model of the Tiny world: dry runs, and trials on a copy with marks."""

    def __init__(self, world: Tiny):
        self.world = world
        self.now = world
        self.trials = 0

    def __call__(self, params) -> bool:
        return self.now.plans(params)

    @contextmanager
    def trial(self):
        self.trials += 1
        model = self

        class Trial:
            def mark(self):
                return model.now.copy()

            def back(self, mark):
                model.now = mark.copy()

            def run(self, params):
                return model.now.run(params)

            def scene_graph(self):
                return model.now.sg()

        self.now = self.world.copy()
        try:
            yield Trial()
        finally:
            self.now = self.world


class Planner:
    """Always the pick of BOX, for its place on shelf_a."""

    def reset(self, goal, seed):
        pass

    def next_action(self, state, goal, refused=frozenset()):
        if Pick(BOX) in refused:
            return TaskDecision.none("nothing left", 0.0)
        return TaskDecision(Pick(BOX), in_grasp(BOX), 0.0, following=Place(BOX, "shelf_a"))


class Motion:
    name = "fake"

    def reset(self, seed):
        pass

    def propose(self, sg, action, following=None, feasible=None):
        if isinstance(action, Pick):
            return PickParams(action.obj)
        return PlaceParams(action.obj, action.target, 0, 0)

    def observe(self, params, outcome):
        pass


def boxed_in() -> Tiny:
    """BOX with a neighbour on each side and one far off."""
    return Tiny(
        {BOX: (0.5, 0.0), "cherries": (0.5, 0.1), "popcorn": (0.5, -0.1), "tomato_soup": (0.9, 0.5)}
    )


GOAL = Goal(frozenset({on(BOX, "shelf_a")}), KITCHEN)


def episode(world: Tiny, clear: bool, steps: int = 8) -> list:
    """The agent's actions, each carried out in `world`, until it takes BOX or the steps end."""
    agent = HierarchicalAgent("fake", Planner(), Motion(), check_actions=True, clear_way=clear)
    agent.reset(GOAL, 0)
    model, taken = Model(world), []
    for _ in range(steps):
        d = agent.decide(world.sg(), world.state(), GOAL, model)
        taken.append(d.action)
        world.run(d.params)
        if d.action == Pick(BOX):
            break
    return taken


def test_two_neighbours_are_moved_aside_one_after_the_other_and_the_box_is_taken_up():
    world = boxed_in()
    taken = episode(world, clear=True)
    assert taken == [
        Pick("cherries"),
        Place("cherries", OPEN_SPACE),
        Pick("popcorn"),
        Place("popcorn", OPEN_SPACE),
        Pick(BOX),
    ]
    assert world.held == BOX and world.xy["tomato_soup"] == (0.9, 0.5)


def test_without_clearing_the_blocked_pick_is_taken_as_the_planner_named_it():
    assert episode(boxed_in(), clear=False) == [Pick(BOX)]


def test_a_tower_top_goes_before_its_base_and_the_base_then_counts():
    world = boxed_in()
    world.xy["popcorn"] = (0.5, 0.1)  # on cherries: one tower beside the box
    world.under["popcorn"] = "cherries"
    assert neighbours(world.sg(), world.state(), GOAL, Pick(BOX), None) == ["popcorn"]
    moved = neighbours(world.sg(), world.state(), GOAL, Pick(BOX), None, ("popcorn",))
    assert moved == ["cherries"]
    assert episode(world, clear=True)[:3] == [
        Pick("popcorn"),
        Place("popcorn", OPEN_SPACE),
        Pick("cherries"),
    ]


def test_a_neighbour_whose_goal_literal_holds_is_moved_last():
    world = boxed_in()
    world.xy["tomato_soup"] = (0.55, 0.0)  # nearest of all, and where the goal wants it
    goal = Goal(frozenset({on(BOX, "shelf_a"), on("tomato_soup", OPEN_SPACE)}), KITCHEN)
    found = neighbours(world.sg(), world.state(), goal, Pick(BOX), None)
    assert found[-1] == "tomato_soup" and set(found) == {"cherries", "popcorn", "tomato_soup"}


def test_no_way_is_cleared_where_moving_neighbours_cannot_free_the_action():
    world = boxed_in()
    world.xy["tomato_soup"] = (0.4, 0.0)  # three neighbours: more than two moves
    model = Model(world)
    blocked = [(Pick(BOX), Place(BOX, "shelf_a"))]
    propose = lambda g, a, f: Motion().propose(g, a, f)  # noqa: E731
    assert find_clearing(world.sg(), world.state(), GOAL, blocked, propose, model) is None
    assert model.now is world and world.held is None  # the trial left the world as it was


def test_clearing_stops_at_its_budget_for_the_episode():
    agent = HierarchicalAgent("fake", Planner(), Motion(), check_actions=True, clear_way=True)
    agent.reset(GOAL, 0)
    for k in range(CLEARINGS + 1):
        world = boxed_in()
        world.xy.pop("popcorn")  # one neighbour: one move clears the way
        d = agent.decide(world.sg(), world.state(), GOAL, Model(world))
        assert d.action == (Pick("cherries") if k < CLEARINGS else Pick(BOX))


def test_a_way_whose_move_failed_is_given_up_and_the_planner_decides():
    agent = HierarchicalAgent("fake", Planner(), Motion(), check_actions=True, clear_way=True)
    agent.reset(GOAL, 0)
    world = boxed_in()
    world.xy.pop("popcorn")
    assert agent.decide(world.sg(), world.state(), GOAL, Model(world)).action == Pick("cherries")
    # the pick failed in the world: nothing is held where the way expected cherries
    d = agent.decide(world.sg(), world.state(), GOAL, Model(world))
    assert d.action == Pick("cherries") and agent._queued  # found again from this scene
