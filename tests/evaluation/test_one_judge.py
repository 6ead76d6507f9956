"""One judge for every observer: each executed step is judged on the simulator's state by
`sim.outcome.judge`, whatever the robot saw, and under the paper's protocol an episode
succeeds only where every step truly succeeded and the goal truly holds."""

import random

import pytest

from hsgplan.agents.registry import make_agent
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.world import GRIPPER_MAX_OPENING
from hsgplan.evaluation.episode import StepRecord, judged_failure, run_episode
from hsgplan.evaluation.failures import Failure
from hsgplan.evaluation.observers import make_observer
from hsgplan.evaluation.summary import failure_class, misread_steps
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.actuation import drive_fingers
from hsgplan.sim.env import KitchenStorageEnv
from hsgplan.sim.scene import Scene
from hsgplan.sim.staging import hold


def _step(status: str, truth: str) -> StepRecord:
    return StepRecord(1, "", "pick(butter)", "", status, "", 0.0, 0.0, 0.0, truth=truth)


OK, FAILED = "success", "disturbed"


@pytest.mark.parametrize(
    ("seen", "steps", "goal_holds", "paper", "failure"),
    [
        # the robot saw all go well; a step truly failed: the paper's protocol fails it
        (None, [(OK, FAILED), (OK, OK)], True, True, Failure.FAILED_PRIMITIVE),
        # ... and the recovering protocol counts the verdict but judges the goal
        (None, [(OK, FAILED), (OK, OK)], True, False, None),
        # a stop on a step seen to fail that truly succeeded: short of the goal, misjudged
        (Failure.FAILED_PRIMITIVE, [(FAILED, OK)], False, True, Failure.MISJUDGED),
        # ... where the goal truly holds and every step truly succeeded, a success
        (Failure.FAILED_PRIMITIVE, [(FAILED, OK)], True, True, None),
        (Failure.FAILED_PRIMITIVE, [(FAILED, FAILED)], True, True, Failure.FAILED_PRIMITIVE),
        (None, [(OK, OK)], False, True, Failure.MISPERCEIVED),
        (None, [(OK, OK)], True, True, None),
        (Failure.OVERSTEP, [(OK, OK)], False, False, Failure.OVERSTEP),
    ],
)
def test_an_episode_is_judged_on_the_verdicts_and_the_true_goal(
    seen, steps, goal_holds, paper, failure
):
    records = [_step(s, t) for s, t in steps]
    assert judged_failure(seen, records, goal_holds, paper) == failure


def test_steps_the_robot_read_otherwise_than_the_judge_are_counted():
    from hsgplan.evaluation.episode import EpisodeRecord

    steps = (_step(OK, FAILED), _step(FAILED, OK), _step(OK, OK), _step(OK, ""))
    record = EpisodeRecord(0, "oracle", "", 1, False, 0.0, "failed_primitive", steps, 0.0)
    assert misread_steps([record]) == {"seen_ok_truly_failed": 1, "seen_failed_truly_ok": 1}
    # the step that failed the episode is the first the judge failed
    assert failure_class(record) == ("execution", FAILED)


def test_an_object_lifted_by_friction_alone_is_held_until_it_slips_out():
    with Scene(["butter"], seed=0, visuals=False, world=KITCHEN) as scene:
        robot = scene.robot
        assert hold(scene, "butter", random.Random(1))
        robot.detach()  # no constraint: the fingers alone hold it
        drive_fingers(robot, 0.0)
        robot.carry(scene.bodies["butter"])
        scene.settle()
        scene.feel_hold()
        assert scene.held() == "butter"
        assert scene.scene_graph().held == "butter"
        drive_fingers(robot, GRIPPER_MAX_OPENING)
        scene.settle()
        scene.feel_hold()
        assert scene.held() is None and robot.held_body is None


# seed 3: f_p sees the soup move 2.9 cm, within what its looks cannot tell from their spread
SEED = 3


@pytest.mark.slow
@pytest.mark.parametrize("observer", ["gt", "rgb"])
def test_a_disturbance_the_cameras_missed_fails_the_episode_for_every_observer(observer):
    goal = parse_goal("On(butter, shelf_a)", world=KITCHEN)
    env = KitchenStorageEnv(observer=make_observer(observer), world=KITCHEN)
    nudged = []

    def nudge():  # the soup slides 3 cm as the pick begins: more than the judge allows
        if not nudged:
            p = env.scene.pose("tomato_soup")
            x, y, z = p.position
            env.scene.set_pose("tomato_soup", Pose((x, y + 0.03, z), p.orientation))
            nudged.append(p)

    record = run_episode(
        env,
        make_agent("oracle"),
        goal,
        SEED,
        on_frame=nudge,
        end_at_failure=True,
        others=("tomato_soup",),
    )
    pick = record.steps[0]
    assert pick.truth == "disturbed" and "tomato_soup" in pick.truth_detail
    # under the ground truth the robot's reading is the judge's; through f_p it saw no harm
    assert pick.status == ("disturbed" if observer == "gt" else "success")
    assert not record.success
    assert failure_class(record) == ("execution", "disturbed")
