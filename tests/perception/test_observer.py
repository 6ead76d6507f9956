"""f_p behind the observer interface: naming detections after the objects they are (tracks by
type and last pose), and the whole loop run on what a camera observer makes of the scene. The
network is replaced by one that outputs the scene's true maps, so that the loop's plumbing,
decoding, PnP and fusion are checked without a trained checkpoint."""

import math
from dataclasses import replace
from functools import partial

import numpy as np
import pytest
import torch

from hsgplan.agents.registry import make_agent
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.parameters import PickParams
from hsgplan.domain.recovery import RecoveryRules
from hsgplan.evaluation.episode import run_episode
from hsgplan.evaluation.failures import Failure
from hsgplan.perception.detection import Detection
from hsgplan.perception.estimator import PoseEstimator
from hsgplan.perception.keypoints import PinholeCamera, in_world, view_keypoints
from hsgplan.perception.maps import targets
from hsgplan.perception.model import STRIDE
from hsgplan.perception.observer import (
    HAND_RADIUS,
    RgbObserver,
    assign,
    away_from_hand,
    first_sight,
    tracked,
)
from hsgplan.perception.vocabulary import kitchen_vocabulary
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.env import KitchenStorageEnv
from hsgplan.sim.outcome import Status
from hsgplan.sim.sensing import Look, Seen

VIEWS = kitchen_vocabulary().views  # the shipped f_p's fixed cameras

TYPES = list(KITCHEN.object_types)


def _at(type_name: str, x: float, y: float, score: float = 0.9) -> Detection:
    return Detection(type_name, Pose.from_xyz_yaw(x, y, 0.05), score, 2, 1.0)


def test_a_lone_object_takes_its_types_strongest_detection_wherever_it_is():
    last = {"butter": Pose.from_xyz_yaw(0.5, 0.0, 0.05)}
    found = assign([_at("butter", 0.2, 0.3, 0.5), _at("butter", 0.9, -0.3, 0.8)], last, KITCHEN)
    assert found["butter"].position[:2] == (0.9, -0.3)


def test_duplicates_keep_their_names_and_one_put_down_elsewhere_is_found_by_elimination():
    last = {
        "cherries": Pose.from_xyz_yaw(0.5, 0.0, 0.05),
        "cherries_2": Pose.from_xyz_yaw(0.5, 0.2, 0.05),
        "cherries_3": Pose.from_xyz_yaw(0.3, -0.2, 0.05),
    }
    detections = [_at("cherries", 0.51, 0.2), _at("cherries", 0.49, 0.0), _at("cherries", 0.9, 0.6)]
    found = assign(detections, last, KITCHEN)
    assert found["cherries"].position[:2] == (0.49, 0.0)
    assert found["cherries_2"].position[:2] == (0.51, 0.2)
    assert found["cherries_3"].position[:2] == (0.9, 0.6)  # moved far: the one left over
    # with one detection too many, the one put down elsewhere takes the nearer far one
    found = assign(
        [*detections[:2], _at("cherries", 0.3, 0.5), _at("cherries", 0.95, 0.6)], last, KITCHEN
    )
    assert found["cherries_3"].position[:2] == (0.3, 0.5)


def test_an_object_that_stayed_is_known_by_where_it_is_whatever_type_f_p_named():
    last = {
        "butter": Pose.from_xyz_yaw(0.5, 0.0, 0.012),
        "cream_cheese": Pose.from_xyz_yaw(0.6, 0.3, 0.012),  # in the hand, then put down
        "cherries": Pose.from_xyz_yaw(0.4, -0.2, 0.03),
    }
    # the cream cheese now on the butter; the butter's centroid shows cream cheese's colour
    detections = [
        _at("cream_cheese", 0.501, 0.0),
        _at("cream_cheese", 0.5, 0.01, 0.8),
        _at("tomato_soup", 0.4, -0.2),
    ]
    found = assign(detections, last, KITCHEN)
    assert found["butter"].position[:2] == (0.501, 0.0)
    assert found["cream_cheese"].position[:2] == (0.5, 0.01)
    assert found["cherries"].position[:2] == (0.4, -0.2)  # still where it was
    far = assign([_at("popcorn", 0.9, 0.5)], {"butter": last["butter"]}, KITCHEN)
    assert far == {}  # another type, far from where the butter was: not the butter


class _SceneMaps(torch.nn.Module):
    """Outputs the true maps of the scene it is given (every object, hidden or not)."""

    stride = STRIDE

    def __init__(self) -> None:
        super().__init__()
        self.scene = None
        self.hidden: str | None = None  # an object it does not draw

    def last(self, images):  # what a look reads of a keypoint network
        return self(images)[-1]

    def forward(self, images):
        poses = {o: p for o, p in self.scene.poses().items() if o != self.hidden}
        kinds = np.array([TYPES.index(KITCHEN.type_of(o)) for o in poses])
        height, width = images.shape[2] // STRIDE, images.shape[3] // STRIDE
        maps = []
        for camera in VIEWS:
            pinhole = PinholeCamera.of(camera)
            points = np.stack(
                [view_keypoints(KITCHEN.object_type(o), p, pinhole) for o, p in poses.items()]
            )
            maps.append(targets(points, kinds, len(TYPES), height, width))
        return [
            (
                torch.from_numpy(np.stack([b for b, _ in maps])),
                torch.from_numpy(np.stack([f for _, f in maps])),
            )
        ]


class _Watching(RgbObserver):
    """The observer with the stand-in network, which the test lets draw the env's scene."""

    def __init__(self, estimator: PoseEstimator) -> None:
        super().__init__(estimator)
        self.env: KitchenStorageEnv | None = None
        self.looks: list[Look] = []

    def look(self, look: Look) -> Seen:
        self.looks.append(look)
        self.estimator.net.scene = self.env.scene
        return super().look(look)


def _watched_env(**kwargs) -> tuple[KitchenStorageEnv, _Watching]:
    observer = _Watching(PoseEstimator(_SceneMaps()))
    env = KitchenStorageEnv(observer=observer, **({"world": KITCHEN} | kwargs))
    observer.env = env
    return env, observer


def test_the_loop_runs_on_what_the_cameras_make_of_the_scene_and_is_judged_on_the_truth():
    env, observer = _watched_env()
    goal = parse_goal("On(butter, shelf_b) & On(cherries, butter)", world=KITCHEN)
    record = run_episode(env, make_agent("oracle"), goal, seed=4)
    assert record.observer == "rgb"
    assert record.success and record.failure is None, record.steps
    assert record.unseen_objects == 0
    # a look is the images, the calibration, the joints and the hand's own record: no scene
    first = observer.looks[0]
    assert first.images.shape[0] == len(first.cameras) == len(VIEWS)
    assert first.holding is None and first.held_pose is None and first.released is None
    assert any(look.holding == "cherries" for look in observer.looks)
    assert any(look.released and look.released[0] == "cherries" for look in observer.looks)


def test_the_robot_plans_in_its_belief_and_the_world_only_runs_the_joints():
    """A belief 10 cm off the butter's true place: the pick is planned there, the fingers close
    on nothing, and the step is judged by the gripper (dropped), not by the truth."""

    class Shifted(_Watching):
        def look(self, look: Look) -> Seen:
            seen = super().look(look)
            poses = {n.name: n.pose for n in seen.scene_graph.nodes}
            x, y, z = poses["butter"].position
            poses["butter"] = replace(poses["butter"], position=(x + 0.1, y, z))
            sg = GeometricSceneGraph.from_poses(poses, held=seen.scene_graph.held, world=KITCHEN)
            return replace(seen, scene_graph=sg)

    observer = Shifted(PoseEstimator(_SceneMaps()))
    env = KitchenStorageEnv(observer=observer, world=KITCHEN)
    observer.env = env
    _, info = env.reset(seed=4, options={"goal": "On(butter, shelf_b)"})
    believed = info["observation"].scene_graph.pose("butter")
    assert believed.distance(env.scene.pose("butter")) == pytest.approx(0.1, abs=1e-6)
    _, _, _, _, info = env.step(PickParams("butter"))
    outcome = info["outcome"]
    assert outcome.status is Status.DROPPED and "closed on nothing" in outcome.detail
    assert env.scene.held() is None and env.world.holding is None
    env.close()


def test_a_pick_at_the_belief_holds_whatever_the_fingers_close_on():
    env, _ = _watched_env()
    env.reset(seed=4, options={"goal": "On(butter, shelf_b)"})
    _, _, _, _, info = env.step(PickParams("butter"))
    assert info["outcome"].ok, info["outcome"]
    assert env.scene.held() == "butter" and env.world.holding == "butter"
    # the robot's record of where it holds the butter is the grasp as planned, near the truth
    held = info["observation"].scene_graph
    assert held.held == "butter"
    assert held.pose("butter").distance(env.scene.pose("butter")) < 0.01
    env.close()


@pytest.mark.parametrize("seek", [True, False])
def test_an_object_no_view_has_found_has_no_pose_and_ends_the_episode_as_never_seen(seek):
    class Blind(_Watching):  # finds everything but the butter
        def look(self, look: Look) -> Seen:
            self.estimator.net.hidden = "butter"
            return super().look(look)

    observer = Blind(PoseEstimator(_SceneMaps()))
    rules = replace(RecoveryRules(), seek_unseen=seek)
    env = KitchenStorageEnv(observer=observer, rules=rules, world=KITCHEN)
    observer.env = env
    goal = parse_goal("On(butter, shelf_b) & On(cherries, shelf_a)", world=KITCHEN)
    record = run_episode(env, make_agent("oracle"), goal, seed=4)
    assert record.failure == Failure.NEVER_SEEN
    if seek:  # the seen part of the goal reached first, and then no more to do
        assert record.steps and all("cherries" in s.action for s in record.steps)
        assert record.subgoal_completion == 0.5
    else:
        assert record.steps == ()


def test_tracks_start_from_the_first_look_never_from_a_staged_pose():
    observer = RgbObserver(PoseEstimator(_SceneMaps()))
    observer.start(("butter", "tomato_soup"), KITCHEN)
    soup = Pose.from_xyz_yaw(0.5, 0.1, KITCHEN.object_types["tomato_soup"].size[2] / 2)
    lone = Detection("tomato_soup", soup, 0.9, 1, 1.0)
    observer.estimator.detect = lambda images, cameras, world, arm: [lone]
    look = Look(np.zeros((1, 2, 2, 3), np.uint8), VIEWS[:1], np.zeros(7))
    seen = observer.look(look)
    assert seen.scene_graph.objects == ("tomato_soup",)
    assert seen.unknown == ("butter",) and set(seen.uncertain) == {"butter", "tomato_soup"}
    butter = Pose.from_xyz_yaw(0.3, -0.2, KITCHEN.object_types["butter"].size[2] / 2)
    both = [replace(lone, views=3), Detection("butter", butter, 0.8, 2, 1.0)]
    observer.estimator.detect = lambda images, cameras, world, arm: both
    seen = observer.look(look)
    assert seen.unknown == () and seen.uncertain == ()
    assert seen.scene_graph.pose("butter") == butter


def test_first_sight_names_a_type_by_the_surest_detection_and_a_misnamed_one_by_its_kind():
    weak, sure = _at("butter", 0.2, 0.3, 0.5), replace(_at("butter", 0.6, 0.3, 0.4), views=4)
    assert first_sight((weak, sure), ["butter"], ("butter",), KITCHEN) == {"butter": sure}
    # no cream cheese in the episode: a detection named so is the butter misnamed
    misnamed = _at("cream_cheese", 0.4, 0.1)
    assert first_sight((misnamed,), ["butter"], ("butter",), KITCHEN) == {"butter": misnamed}
    # a popcorn in the episode, already seen: a second one is its phantom, not the butter
    assert (
        first_sight((_at("popcorn", 0.4, 0.1),), ["butter"], ("butter", "popcorn"), KITCHEN) == {}
    )


def test_a_goal_only_seen_reached_is_a_failure_of_perception():
    class Fooled:  # sees the cherries on the butter, wherever they are
        name = "fooled"

        def reset(self, scene) -> None:
            pass

        def observe(self, scene) -> Seen:
            sg = scene.scene_graph()
            butter, cherries = sg.node("butter"), sg.node("cherries")
            lift = cherries.pose.position[2] - cherries.bottom_z
            x, y, _ = butter.pose.position
            poses = {n.name: n.pose for n in sg.nodes}
            poses["cherries"] = Pose((x, y, butter.top_z + lift), cherries.pose.orientation)
            return Seen(GeometricSceneGraph.from_poses(poses, held=sg.held, world=KITCHEN))

    env = KitchenStorageEnv(observer=Fooled(), world=KITCHEN)
    record = run_episode(
        env, make_agent("oracle"), parse_goal("On(cherries, butter)", world=KITCHEN), seed=4
    )
    assert record.observer == "fooled" and record.steps == ()
    assert not record.success and record.failure == Failure.MISPERCEIVED
    assert record.subgoal_completion == 0.0


def test_the_estimate_is_drawn_where_the_camera_sees_it():
    from hsgplan.perception.draw import COLOR, draw_cuboids

    camera = VIEWS[0]
    image = np.zeros((camera.height, camera.width, 3), dtype=np.uint8)
    pose = Pose.from_xyz_yaw(0.5, 0.0, 0.05, 0.3)
    drawn = draw_cuboids(image, camera, {"popcorn": pose}, KITCHEN)
    u, v = np.round(
        PinholeCamera.of(camera).project(in_world(KITCHEN.object_type("popcorn"), pose))[-1]
    ).astype(int)
    assert tuple(drawn[v, u]) == COLOR  # the centroid's dot
    assert (drawn.any(axis=2)).sum() > 100 and not image.any()  # edges drawn, on a copy


def test_eval_sees_through_the_shipped_f_p_beside_the_ground_truth(tmp_path):
    import json

    from typer.testing import CliRunner

    from hsgplan.cli import app

    r = CliRunner().invoke(
        app,
        ["eval", "world", "--agent", "learned", "--sizes", "2", "--goals", "1", "--workers", "1"]
        + ["--perception", "gt,rgb", "--json", "--out", str(tmp_path / "run")],
    )
    assert r.exit_code == 0, r.output
    methods = json.loads(r.stdout)["methods"]
    assert methods["learned"]["perception"] == "gt"
    assert methods["learned-rgb"]["perception"] == "rgb"
    assert methods["learned-rgb"]["by_size"]["2"]["episodes"] == 1
    (line,) = (tmp_path / "run" / "learned-rgb" / "episodes.jsonl").read_text().splitlines()
    assert json.loads(line)["result"]["observer"] == "rgb"


def test_a_lone_views_detection_of_another_type_far_from_where_an_object_was_is_not_it():
    last = {"butter": Pose.from_xyz_yaw(0.5, 0.0, 0.012)}
    lone = Detection("cream_cheese", Pose.from_xyz_yaw(0.6, 0.0, 0.012), 0.9, 1, 1.0)
    assert assign([lone], last, KITCHEN) == {}  # 10 cm off, one view, another type: a phantom
    both = replace(lone, views=2)
    assert assign([both], last, KITCHEN)["butter"] == both.pose
    near = replace(lone, pose=Pose.from_xyz_yaw(0.52, 0.0, 0.012))
    assert assign([near], last, KITCHEN)["butter"] == near.pose  # where it was: its colour misled


def test_an_object_unseen_under_a_can_still_holds_the_can_up():
    butter = Pose.from_xyz_yaw(0.5, 0.0, KITCHEN.object_types["butter"].size[2] / 2)
    top = KITCHEN.object_types["butter"].size[2]
    can_half = KITCHEN.object_types["tomato_soup"].size[2] / 2
    measured = Pose.from_xyz_yaw(0.5, 0.005, top + can_half - 0.003)  # seen on it, nearly
    can = Detection("tomato_soup", measured, 0.9, 3, 1.0, measured=measured)
    (alone,) = PoseEstimator.rest(KITCHEN, [can])
    assert alone.pose.position[2] == pytest.approx(can_half)  # nothing found under it
    (held_up,) = PoseEstimator.rest(KITCHEN, [can], [("butter", butter)])
    assert held_up.pose.position[2] == pytest.approx(top + can_half)
    # on its side, so nothing to rest on: left where it was seen, inside the table
    lying = Pose((0.5, 0.0, -0.15), (math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5)))
    assert PoseEstimator.rest(KITCHEN, [replace(can, measured=lying)]) == []  # nothing can be there
    (above,) = PoseEstimator.rest(
        KITCHEN, [replace(can, measured=replace(lying, position=(0.5, 0, 0.05)))]
    )
    assert above.pose.position[2] == 0.05  # over the table, left as it was seen


def test_the_tracker_keeps_a_hidden_butter_where_it_was_and_the_can_on_it_up():
    butter = Pose.from_xyz_yaw(0.5, 0.0, KITCHEN.object_types["butter"].size[2] / 2)
    top, can_half = (
        KITCHEN.object_types["butter"].size[2],
        KITCHEN.object_types["tomato_soup"].size[2] / 2,
    )
    measured = Pose.from_xyz_yaw(0.5, 0.005, top + can_half - 0.003)
    (seen,) = PoseEstimator.rest(
        KITCHEN,
        [Detection("tomato_soup", measured, 0.9, 3, 1.0, measured=measured)],
    )
    last = {"butter": butter, "tomato_soup": Pose.from_xyz_yaw(0.5, 0.0, top + can_half)}
    tracks = tracked([seen], last, KITCHEN)
    poses = tracks.poses
    assert tracks.unseen == ("butter",) and poses["butter"] == butter
    assert poses["tomato_soup"].position[2] == pytest.approx(can_half)  # sunk onto the table
    tracks = tracked([seen], last, KITCHEN, partial(PoseEstimator.rest, KITCHEN))
    poses = tracks.poses
    assert tracks.unseen == ("butter",) and poses["butter"] == butter
    assert tracks.left == () and set(tracks.found) == {"tomato_soup"}
    assert poses["tomato_soup"].position[2] == pytest.approx(top + can_half)  # on the butter


def test_a_lone_views_butter_is_put_where_its_ray_passes_its_last_pose_and_holds_its_can_up():
    half, can_half = (
        KITCHEN.object_types["butter"].size[2] / 2,
        KITCHEN.object_types["tomato_soup"].size[2] / 2,
    )
    butter = Pose.from_xyz_yaw(
        0.45, 0.35, KITCHEN.shelves["shelf_a"].top.z + half, 0.0
    )  # on shelf A's top
    eye = np.array(VIEWS[1].eye)
    ray = (eye, (np.array(butter.position) - eye) / np.linalg.norm(butter.position - eye))
    # one view saw a strip of it; PnP put it far along that view's line of sight, on the table
    table = eye + ray[1] * (half - eye[2]) / ray[1][2]
    wrong = Pose.from_xyz_yaw(*table, 0.0)
    lone = Detection("butter", wrong, 0.9, 1, 1.0, rays=(ray,), measured=wrong)
    measured = Pose.from_xyz_yaw(
        0.45, 0.35, KITCHEN.shelves["shelf_a"].top.z + 2 * half + can_half - 0.004
    )
    can = Detection("tomato_soup", measured, 0.9, 3, 1.0, measured=measured)
    found = PoseEstimator.rest(KITCHEN, [lone, can])
    assert found[0].pose.position[2] == pytest.approx(half)  # on the table, far off
    last = {"butter": butter, "tomato_soup": replace(measured, position=(0.45, 0.35, 0.3))}
    tracks = tracked(found, last, KITCHEN, partial(PoseEstimator.rest, KITCHEN))
    poses = tracks.poses
    assert tracks.unseen == () and np.allclose(poses["butter"].position, butter.position, atol=1e-6)
    assert poses["tomato_soup"].position[2] == pytest.approx(
        KITCHEN.shelves["shelf_a"].top.z + 2 * half + can_half
    )
    # a lone view's ray far from where the object was leaves its estimate as it was measured
    moved = {**last, "butter": Pose.from_xyz_yaw(0.45, 0.0, half, 0.0)}
    poses = tracked(found, moved, KITCHEN, partial(PoseEstimator.rest, KITCHEN)).poses
    assert poses["butter"].position == pytest.approx(found[0].pose.position)


class _Unsure(_Watching):
    """Reports every object uncertain, as if a single view saw each."""

    def look(self, look: Look) -> Seen:
        seen = super().look(look)
        return replace(seen, uncertain=seen.scene_graph.objects)


@pytest.mark.parametrize("relook", [True, False])
def test_an_uncertain_object_is_looked_at_again_from_out_of_the_way_unless_the_rule_is_off(
    relook,
):
    observer = _Unsure(PoseEstimator(_SceneMaps()))
    rules = replace(RecoveryRules(), relook=relook)
    env = KitchenStorageEnv(observer=observer, rules=rules, world=KITCHEN)
    observer.env = env
    goal = parse_goal("On(butter, shelf_b) & On(cherries, shelf_a)", world=KITCHEN)
    record = run_episode(env, make_agent("oracle"), goal, seed=4)
    assert record.success, record.steps
    looks = sum(s.relooks for s in record.steps)
    # the first step starts at rest, where a look would see what the last one saw
    assert record.steps[0].relooks == 0
    assert (looks == len(record.steps) - 1) if relook else looks == 0
    # and once more before it believes the goal reached, the arm having stopped elsewhere
    assert record.closing_relooks == (1 if relook else 0)
    assert len(observer.looks) == 1 + len(record.steps) + looks + record.closing_relooks


def test_what_f_p_measured_at_the_hand_is_no_other_object_wherever_it_was_made_to_rest():
    hand = Pose.from_xyz_yaw(0.45, 0.0, 0.15, 0.0)
    rested = Pose.from_xyz_yaw(0.45, 0.0, 0.0415, 0.0)  # dropped onto the table under the hand
    held = Detection("tomato_soup", rested, 0.9, 5, 0.0, measured=hand)
    other = Detection("tomato_soup", Pose.from_xyz_yaw(0.45, 0.2, 0.0415, 0.0), 0.9, 5, 0.0)
    assert math.dist(rested.position, hand.position) > HAND_RADIUS
    assert away_from_hand([held, other], hand) == [other]
    assert away_from_hand([held, other], None) == [held, other]
