"""A still object keeps the belief of the look more views saw it in (`observer.steadied`): a
look in which the arm hides it from a view does not swing its yaw."""

import math

import numpy as np

from hsgplan.domain.kitchen import KITCHEN
from hsgplan.perception.detection import Detection
from hsgplan.perception.estimator import PoseEstimator
from hsgplan.perception.observer import STEADY, RgbObserver, steadied
from hsgplan.perception.vocabulary import kitchen_vocabulary
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.sensing import Look

VIEWS = kitchen_vocabulary().views  # the shipped f_p's fixed cameras

Z = KITCHEN.object_types["popcorn"].size[2] / 2


def _seen(x: float, yaw: float, views: int) -> Detection:
    return Detection("popcorn", Pose.from_xyz_yaw(x, 0.2, Z, yaw), 0.9, views, 1.0)


def _yaw(pose: Pose) -> float:
    x, y, z, w = pose.orientation
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def test_a_detection_of_fewer_views_near_the_belief_leaves_the_belief():
    last = {"popcorn": Pose.from_xyz_yaw(0.5, 0.2, Z, 1.5)}
    near = _seen(0.5 + STEADY / 2, 0.7, 3)
    assert steadied({"popcorn": near}, last, {"popcorn": 4}) == last
    # as many views, or a move past STEADY: the look's detection is taken
    assert steadied({"popcorn": near}, last, {"popcorn": 3}) == {}
    assert steadied({"popcorn": _seen(0.5 + 2 * STEADY, 0.7, 3)}, last, {"popcorn": 4}) == {}
    # a belief no sighting stands behind (where the hand let it go) always yields
    assert steadied({"popcorn": near}, last, {}) == {}


def _observer(steady: bool, looks: list[list[Detection]]) -> RgbObserver:
    observer = RgbObserver(PoseEstimator(None), steady=steady)
    observer.estimator.settled = False
    queue = iter(looks)
    observer.estimator.detect = lambda images, cameras, world, arm: next(queue)
    observer.start(("popcorn",), KITCHEN)
    return observer


def _look(**kwargs) -> Look:
    return Look(np.zeros((len(VIEWS), 2, 2, 3), np.uint8), VIEWS, np.zeros(7), **kwargs)


def test_the_observer_keeps_the_richer_sighting_of_a_still_box_and_only_with_the_rule():
    looks = [[_seen(0.5, 1.5, 5)], [_seen(0.503, 0.7, 4)], [_seen(0.504, 0.9, 5)]]
    on, off = _observer(True, looks), _observer(False, looks)
    first = on.look(_look())
    assert off.look(_look()).scene_graph == first.scene_graph
    kept = on.look(_look()).scene_graph.pose("popcorn")
    assert kept == first.scene_graph.pose("popcorn")
    assert math.isclose(_yaw(off.look(_look()).scene_graph.pose("popcorn")), 0.7, abs_tol=1e-6)
    # as many views as the belief's: the new sighting is taken
    assert math.isclose(_yaw(on.look(_look()).scene_graph.pose("popcorn")), 0.9, abs_tol=1e-6)


def test_an_object_let_go_takes_the_next_sighting_however_few_views_saw_it():
    put = Pose.from_xyz_yaw(0.5, 0.2, Z, 0.0)
    observer = _observer(True, [[_seen(0.5, 1.5, 5)], [], [_seen(0.502, 0.4, 2)]])
    observer.look(_look())
    observer.look(_look(holding="popcorn", held_pose=Pose.from_xyz_yaw(0.3, 0.0, 0.4)))
    # the held object's pose was the robot's own, as sure as every view: not a sighting
    seen = observer.look(_look(released=("popcorn", put)))
    assert math.isclose(_yaw(seen.scene_graph.pose("popcorn")), 0.4, abs_tol=1e-6)


def test_rgb_latest_is_f_p_with_the_rule_off_and_records_so():
    from hsgplan.evaluation.observers import make_observer

    on, off = make_observer("rgb"), make_observer("rgb-latest")
    assert on.steady and on.name == "rgb"
    assert not off.steady and off.name == "rgb-latest"
