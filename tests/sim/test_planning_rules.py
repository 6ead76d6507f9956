"""The planner's cheap refusals and detours: each gives the answer the expensive path would."""

import contextlib
import math

import numpy as np
import pytest

from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.parameters import PickParams, PlaceParams, PushParams, place_xy
from hsgplan.domain.world import PLACE_BINS, PUSH_DIST_BINS
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.motion import MotionPlanner
from hsgplan.sim.motion_plans import MotionPlan, plan_primitive
from hsgplan.sim.outcome import Status
from hsgplan.sim.plan_rules import PlanRules
from hsgplan.sim.primitives import execute
from hsgplan.sim.robot import ARM
from hsgplan.sim.scene import Scene

from .conftest import standing


@pytest.fixture
def scene():
    s = Scene(
        ["cherries", "tomato_soup", "butter"],
        seed=0,
        poses={
            "cherries": standing("cherries", 0.42, 0.05),
            "butter": standing("butter", 0.55, -0.10),
            "tomato_soup": standing("tomato_soup", 0.305, 0.38),
        },
        world=KITCHEN,
    )
    s.settle()
    yield s
    s.close()


def _unmoved(scene, before):
    return all(scene.pose(n).distance(p) < 1e-6 for n, p in before.items())


def test_a_push_too_short_to_reach_the_shelf_is_refused_and_moves_nothing(scene):
    before = scene.poses()
    out = execute(scene, PushParams("tomato_soup", 10, 0))  # straight in, 8 cm: ends at 0.375
    assert out.status is Status.EFFECT_NOT_REACHED and "too short" in out.detail
    assert _unmoved(scene, before)


def test_a_push_whose_hand_would_hit_the_shelf_is_refused_and_moves_nothing(scene):
    # Beside the shelf's side wall, the 21 cm hand cannot follow a can 20 cm in.
    scene.set_pose("tomato_soup", standing("tomato_soup", 0.305, 0.28))
    scene.settle()
    before = scene.poses()
    out = execute(scene, PushParams("tomato_soup", 10, PUSH_DIST_BINS - 1))
    assert out.status is Status.NO_PATH and "hand would hit" in out.detail
    assert _unmoved(scene, before)


def test_the_held_object_is_checked_where_it_would_be_let_go_and_put_back(scene):
    assert execute(scene, PickParams("cherries")).ok
    held_before = scene.pose("cherries")
    near = scene.checker(ignore=("cherries",))
    butter = scene.pose("butter")
    on_butter = Pose((butter.position[0], butter.position[1], 0.035), held_before.orientation)
    free = Pose((0.40, 0.10, 0.035), held_before.orientation)
    assert near.held_collides_at(on_butter)
    assert not near.held_collides_at(free)
    assert scene.pose("cherries").distance(held_before) < 1e-9


def test_placing_where_a_neighbour_stands_fails_without_moving_anything(scene):
    assert execute(scene, PickParams("cherries")).ok
    bx, by, _ = scene.pose("butter").position
    bins = min(
        ((i, j) for i in range(PLACE_BINS) for j in range(PLACE_BINS)),
        key=lambda b: np.hypot(
            *(np.subtract(place_xy("cherries", "open_space", *b, KITCHEN), (bx, by)))
        ),
    )
    before = scene.poses()
    out = execute(scene, PlaceParams("cherries", "open_space", *bins))
    assert out.status is Status.NO_IK, out.detail
    assert _unmoved(scene, before)


class _Robot:
    """Seven joints in [-1, 1]; no physics."""

    lower, upper = -np.ones(len(ARM)), np.ones(len(ARM))

    @contextlib.contextmanager
    def preserved(self):
        yield


class _Wall:
    """A joint-space wall at q0 in (-0.1, 0.1) wherever q1 < 0.5, counting its checks."""

    def __init__(self):
        self.robot, self.calls = _Robot(), 0

    def collides(self, q):
        self.calls += 1
        return abs(q[0]) < 0.1 and q[1] < 0.5

    def segment_free(self, q0, q1):
        n = max(1, int(np.ceil(np.max(np.abs(q1 - q0)) / 0.02)))
        return not any(self.collides(q0 + (q1 - q0) * (i / n)) for i in range(1, n + 1))


def _ends():
    q0, q1 = np.zeros(len(ARM)), np.zeros(len(ARM))
    q0[0], q1[0] = -0.5, 0.5
    return q0, q1


def test_a_free_detour_is_taken_before_any_tree_search():
    wall = _Wall()
    q0, q1 = _ends()
    over = q0.copy()
    over[:2] = (0.0, 0.8)
    blocked = q0.copy()  # a detour through the wall is passed over
    blocked[:2] = (0.0, 0.0)
    path = MotionPlanner(wall).plan(q0, q1, vias=[lambda: [blocked], lambda: [over]])
    assert [p.tolist() for p in path] == [q0.tolist(), over.tolist(), q1.tolist()]


def test_tree_search_finds_a_way_around_and_repeats_it_exactly():
    q0, q1 = _ends()
    first = MotionPlanner(_Wall()).plan(q0, q1)
    second = MotionPlanner(_Wall()).plan(q0, q1)
    assert first is not None and len(first) > 2
    assert all(np.array_equal(a, b) for a, b in zip(first, second, strict=True))
    wall = _Wall()
    assert all(wall.segment_free(a, b) for a, b in zip(first, first[1:], strict=False))


def test_tree_search_gives_up_after_its_budget_of_checks():
    class Closed(_Wall):
        def collides(self, q):  # the goal side is sealed off: no path exists
            self.calls += 1
            return q[0] > 0.3 and not np.allclose(q[1:], 0.0) or abs(q[0]) < 0.1

    q0, q1 = _ends()
    wall = Closed()
    assert MotionPlanner(wall).plan(q0, q1) is None
    from hsgplan.sim.motion import RRT_CHECKS

    assert RRT_CHECKS <= wall.calls < 2 * RRT_CHECKS


def test_a_grasp_on_another_branch_than_its_descent_is_not_planned(scene, monkeypatch):
    """The pose at the object is solved from the one above it; a solution on another branch
    would swing the arm between the descent's last point and it, through the object a pick's
    checks leave out."""
    from hsgplan.sim import motion_plans

    robot, solve = scene.robot, scene.robot.ik
    asked = []

    def recorded(target, *args, **kwargs):
        asked.append(target.position[2])
        return solve(target, *args, **kwargs)

    def flipped(target, *args, **kwargs):
        q = solve(target, *args, **kwargs)
        if q is not None and abs(target.position[2] - min(asked)) < 1e-9:
            q = q.copy()
            q[6] += motion_plans.MAX_JOINT_JUMP + 0.1  # the hand turned about the object
        return q

    q0 = robot.q()
    monkeypatch.setattr(robot, "ik", recorded)
    plan = motion_plans.plan_primitive(scene, PickParams("cherries"))
    assert plan.params == PickParams("cherries")  # the lowest pose asked is the grasp's
    robot.set_q(q0)
    monkeypatch.setattr(robot, "ik", flipped)
    refused = motion_plans.plan_primitive(scene, PickParams("cherries"))
    assert refused.status is Status.NO_IK
    # the rule taken away (`--plan-rules descent_branch=off`): the flipped grasp is taken
    robot.set_q(q0)
    scene.plan_rules = PlanRules(descent_branch=False)
    taken = motion_plans.plan_primitive(scene, PickParams("cherries"))
    scene.plan_rules = PlanRules()
    assert isinstance(taken, MotionPlan)


def test_the_descent_has_as_many_poses_as_its_rule_says(scene):
    q0 = scene.robot.q()
    for points in (3, 0):
        scene.plan_rules = PlanRules(descent_points=points)
        scene.robot.set_q(q0)
        plan = plan_primitive(scene, PickParams("cherries"))
        assert isinstance(plan, MotionPlan) and len(plan.descent) == points
    scene.plan_rules = PlanRules()


def test_a_can_beside_the_base_is_grasped_with_the_hand_turned_half_round():
    """Right before the base the four radial grasps of a tall can run the wrist out of its
    range; the same grasps turned half round reach it."""
    can = "alphabet_soup"
    with Scene([can], poses={can: standing(can, 0.29, 0.0)}, world=KITCHEN) as s:
        s.settle()
        plan = plan_primitive(s, PickParams(can))
        assert isinstance(plan, MotionPlan)
        s.robot.set_q(plan.q_at)
        closing = s.robot.tcp().rotation[:, 1]
        radial = math.atan2(s.pose(can).position[1], s.pose(can).position[0]) + math.pi / 2
        turned = math.degrees((math.atan2(closing[1], closing[0]) - radial) % (2 * math.pi))
        assert 134 < turned < 271  # none of the first four: 0, 45, 90 and -45 degrees
