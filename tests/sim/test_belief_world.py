"""The robot's model of its belief, and a step judged on beliefs: on tiny hand-built scenes."""

import pytest

from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.parameters import PickParams
from hsgplan.domain.predicates import in_grasp, on
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.belief_world import BeliefWorld
from hsgplan.sim.motion_plans import MotionPlan
from hsgplan.sim.outcome import (
    SEEN_DISTURB_TOL,
    Disturbance,
    Status,
    compare,
    disturbances,
    dragged,
    largest_move,
)
from hsgplan.sim.primitives import run_plan
from hsgplan.sim.scene import Scene


def _on_table(name: str, x: float, y: float) -> Pose:
    return Pose.from_xyz_yaw(x, y, KITCHEN.table.z + KITCHEN.object_types[name].size[2] / 2)


def test_the_model_holds_only_what_is_believed_and_parks_what_was_never_seen():
    world = BeliefWorld(("butter", "tomato_soup"), seed=0, world=KITCHEN)
    try:
        butter = _on_table("butter", 0.5, 0.1)
        world.believe(GeometricSceneGraph.from_poses({"butter": butter}, world=KITCHEN))
        assert world.scene.pose("butter").distance(butter) < 1e-6
        parked = world.scene.pose("tomato_soup")
        assert parked.position[0] < 0  # behind the robot: no obstacle, no pose
        assert world.held_pose() is None
    finally:
        world.close()


def test_a_pick_planned_in_the_belief_takes_up_the_true_object_near_it():
    truth = _on_table("butter", 0.5, 0.1)
    off = Pose((0.5, 0.107, truth.position[2]), truth.orientation)  # 7 mm along its long side
    with Scene(("butter",), seed=0, poses={"butter": truth}, world=KITCHEN) as scene:
        world = BeliefWorld(("butter",), seed=0, world=KITCHEN)
        try:
            world.believe(GeometricSceneGraph.from_poses({"butter": off}, world=KITCHEN))
            plan = world.plan(PickParams("butter"))
            assert isinstance(plan, MotionPlan)
            run_plan(scene, plan)
            assert scene.held() == "butter"
            world.executed(plan, gripper_holds=scene.robot.held_body is not None)
            assert world.holding == "butter"
            # the robot's record: where the planned grasp holds it, 7 mm from the truth
            assert world.held_pose().distance(scene.pose("butter")) == pytest.approx(
                0.007, abs=2e-3
            )
        finally:
            world.close()


def test_a_step_is_judged_on_the_belief_before_and_after_it():
    butter, soup = _on_table("butter", 0.5, 0.1), _on_table("tomato_soup", 0.5, -0.2)
    before = GeometricSceneGraph.from_poses({"butter": butter, "tomato_soup": soup}, world=KITCHEN)
    lifted = Pose((0.5, 0.1, 0.3), butter.orientation)
    held = GeometricSceneGraph.from_poses(
        {"butter": lifted, "tomato_soup": soup}, held="butter", world=KITCHEN
    )
    assert compare(before, held, "butter", in_grasp("butter"))[0] is Status.SUCCESS
    # the soup seen 3 cm from where it was believed: the pick disturbed it
    moved = Pose((0.5, -0.17, soup.position[2]), soup.orientation)
    bumped = GeometricSceneGraph.from_poses(
        {"butter": lifted, "tomato_soup": moved}, held="butter", world=KITCHEN
    )
    assert compare(before, bumped, "butter", in_grasp("butter"))[0] is Status.DISTURBED
    # an object first seen after the step was not disturbed by it
    alone = GeometricSceneGraph.from_poses({"butter": butter}, world=KITCHEN)
    status, detail = compare(alone, before, "butter", on("butter", "open_space"))
    assert status is Status.SUCCESS, detail


def _soup_seen_at(dy: float) -> tuple[GeometricSceneGraph, GeometricSceneGraph]:
    """The belief before and after a pick of the butter, the soup seen `dy` m off."""
    butter, soup = _on_table("butter", 0.5, 0.1), _on_table("tomato_soup", 0.5, -0.15)
    lifted = Pose((0.5, 0.1, 0.3), butter.orientation)
    moved = Pose((0.5, -0.15 + dy, soup.position[2]), soup.orientation)
    return (
        GeometricSceneGraph.from_poses({"butter": butter, "tomato_soup": soup}, world=KITCHEN),
        GeometricSceneGraph.from_poses(
            {"butter": lifted, "tomato_soup": moved}, held="butter", world=KITCHEN
        ),
    )


def test_a_belief_judges_only_moves_beyond_its_own_spread_and_of_what_it_is_sure_of():
    before, after = _soup_seen_at(0.025)
    pick = in_grasp("butter")
    assert compare(before, after, "butter", pick)[0] is Status.DISTURBED  # the truth's 2 cm
    assert compare(before, after, "butter", pick, SEEN_DISTURB_TOL)[0] is Status.SUCCESS
    before, after = _soup_seen_at(SEEN_DISTURB_TOL + 0.01)
    sure = frozenset({"butter", "tomato_soup"})
    status, detail = compare(before, after, "butter", pick, SEEN_DISTURB_TOL, sure)
    assert status is Status.DISTURBED and "tomato_soup" in detail
    # a single view saw it (unsure): its depth is judged by the symbolic location it gives
    unsure = frozenset({"butter"})
    assert compare(before, after, "butter", pick, SEEN_DISTURB_TOL, unsure)[0] is Status.SUCCESS
    # seen in another region now: moved out of place, sure of it or not
    elsewhere = _on_table("tomato_soup", *KITCHEN.regions["prepush_b"].center)
    onto = GeometricSceneGraph.from_poses(
        {"butter": after.pose("butter"), "tomato_soup": elsewhere}, held="butter", world=KITCHEN
    )
    assert compare(before, onto, "butter", pick, SEEN_DISTURB_TOL, unsure)[0] is Status.DISTURBED


def test_the_largest_move_seen_leaves_out_the_object_acted_on_and_the_unsure():
    before, after = _soup_seen_at(0.04)
    assert largest_move(before, after, "butter") == pytest.approx(0.04)
    assert largest_move(before, after, "tomato_soup") > 0.2  # the butter, lifted
    assert largest_move(before, after, "butter", frozenset({"butter"})) == 0.0


def test_a_disturbance_is_put_in_the_phase_by_whose_end_it_had_moved():
    still, moved = _on_table("butter", 0.5, 0.1), _on_table("butter", 0.5, 0.12)
    soup = _on_table("tomato_soup", 0.5, -0.2)
    held, put = _on_table("cherries", 0.3, 0.0), _on_table("cherries", 0.3, 0.02)
    before = {"butter": still, "tomato_soup": soup, "cherries": held}
    phases = [
        ("path", {"butter": still, "tomato_soup": soup, "cherries": held}),
        ("approach", {"butter": moved, "tomato_soup": soup, "cherries": held}),
        ("retreat", {"butter": moved, "tomato_soup": soup, "cherries": put}),
    ]
    after = {"butter": moved, "tomato_soup": soup, "cherries": put}
    # cherries is the primitive's own object: never a disturbance
    assert disturbances(before, after, "cherries", phases) == (
        Disturbance("butter", 0.02, "approach"),
    )
    # without phases told, where it moved is unknown
    assert disturbances(before, after, "cherries") == (Disturbance("butter", 0.02, ""),)
    # the retreat dragged cherries 2 cm after a release let it go; a pick lets nothing go
    released = [phases[0], ("release", phases[0][1]), ("retreat", after)]
    assert dragged(released, after, "cherries") == pytest.approx(0.02)
    assert dragged(released, after, "tomato_soup") == 0.0
    assert dragged(phases, after, "cherries") == 0.0
    pushed = [phases[0], ("push", phases[0][1]), ("retreat", after)]
    assert dragged(pushed, after, "cherries") == 0.0  # a pushed object slides on by design


def test_a_push_leaves_its_object_in_the_model_where_its_stroke_ends():
    import math

    from hsgplan.domain.parameters import PUSH_LEAD, PushParams, push_values
    from hsgplan.domain.world import PUSH_ANGLE_BINS, PUSH_DIST_BINS

    can = _on_table("tomato_soup", 0.30, 0.37)  # on shelf A's prepush region
    world = BeliefWorld(("tomato_soup",), seed=0, world=KITCHEN)
    try:
        world.believe(GeometricSceneGraph.from_poses({"tomato_soup": can}, world=KITCHEN))
        plans = (
            world.plan(PushParams("tomato_soup", a, d))
            for a in range(PUSH_ANGLE_BINS)
            for d in range(PUSH_DIST_BINS - 1, -1, -1)
        )
        plan = next(p for p in plans if isinstance(p, MotionPlan))
        name, end = world.executed(plan, gripper_holds=False)
        angle, dist = push_values(plan.params.angle_bin, plan.params.dist_bin)
        assert name == "tomato_soup"
        along = (dist - PUSH_LEAD) * math.cos(angle), (dist - PUSH_LEAD) * math.sin(angle)
        assert end.position[0] == pytest.approx(can.position[0] + along[0], abs=1e-6)
        assert end.position[1] == pytest.approx(can.position[1] + along[1], abs=1e-6)
        assert end.position[2] == pytest.approx(can.position[2])
        assert world.holding is None
    finally:
        world.close()
