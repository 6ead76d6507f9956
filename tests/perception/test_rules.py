"""f_p's rules can be set by name, and each switch changes what its rule decides: a rule is
measured against its absence, so its absence must be the rule taken away, not a no-op."""

import math
from dataclasses import replace

import numpy as np
import pytest

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.perception.apart import apart
from hsgplan.perception.detection import Detection
from hsgplan.perception.estimator import PoseEstimator
from hsgplan.perception.fusion import RAY_GAP, along_ray_near, grouped, line_of_sight, ray_gap
from hsgplan.perception.observer import assign, assigned
from hsgplan.perception.rules import SHIPPED, PerceptionRules
from hsgplan.scene_graph.geometry import Pose
from tests.perception.test_fusion import _seen


def test_settings_are_read_by_name_and_written_back_as_they_differ_from_the_shipped():
    rules = PerceptionRules.parse("pixel_vote=off, ray_gap=0.03")
    assert rules == replace(SHIPPED, pixel_vote=False, ray_gap=0.03)
    assert rules.changed() == ("ray_gap=0.03", "pixel_vote=off")
    assert PerceptionRules.parse(rules.changed()) == rules
    assert PerceptionRules.parse("") == SHIPPED and SHIPPED.changed() == ()
    assert SHIPPED.ray_gap == RAY_GAP  # the defaults are the modules' constants


@pytest.mark.parametrize(
    "bad",
    ["bogus=1", "pixel_vote", "pixel_vote=maybe", "ray_gap=-1", "ray_gap=far", "near_ray=inf"],
)
def test_a_bad_setting_is_refused_in_one_line(bad):
    with pytest.raises(InvalidInputError, match="perception rule"):
        PerceptionRules.parse(bad)


def test_without_cliques_the_closest_pair_of_rays_is_joined_first():
    # two views' rays to two objects pass closer than an object's own: the cliques keep the
    # object every view saw whole, the closest pairs first break it up
    top = np.array([0.45, 0.25, 0.18])
    eye0, eye1 = _seen(top, 0, 0.9).keypoints.camera.eye, _seen(top, 1, 0.8).keypoints.camera.eye
    ghost = top + 0.1 * (eye0 - top) / np.linalg.norm(eye0 - top)
    below = ghost + 0.12 * (ghost - eye1) / np.linalg.norm(ghost - eye1)
    t0, t1, t2 = (
        _seen(top, 0, 0.9),
        _nudged(_seen(top, 1, 0.8), 1.0),
        _nudged(_seen(top, 2, 0.7), -1.0),
    )
    b1, b2 = _seen(below, 1, 0.6), _seen(below, 2, 0.5)
    found = [t0, t1, t2, b1, b2]
    whole = {frozenset(map(id, g)) for g in grouped(found, KITCHEN.table)}
    pairs = {frozenset(map(id, g)) for g in grouped(found, KITCHEN.table, cliques=False)}
    assert ray_gap(t0, b1, KITCHEN.table) < ray_gap(t0, t1, KITCHEN.table)
    assert frozenset(map(id, (t0, t1, t2))) in whole
    assert any({id(t0), id(b1)} <= g for g in pairs)  # the ghost pair, joined first
    assert frozenset(map(id, (t0, t1, t2))) not in pairs
    # no view twice in a group either way, and every instance in one group
    for groups in (grouped(found, KITCHEN.table, cliques=False),):
        assert sorted(id(s) for g in groups for s in g) == sorted(map(id, found))
        assert all(len({s.view for s in g}) == len(g) for g in groups)


def _nudged(s, du: float):  # a pixel off: the object's own rays miss a little
    pixels = s.keypoints.pixels.copy()
    pixels[-1, 0] += du
    return replace(s, keypoints=replace(s.keypoints, pixels=pixels))


def test_a_narrower_ray_gap_joins_fewer_views():
    p = np.array([0.5, 0.0, 0.03])
    a, b = _seen(p, 0, 0.9), _seen(p + [0.0, 0.004, 0.0], 1, 0.8)  # rays 4 mm or so apart
    assert len(grouped([a, b], KITCHEN.table)) == 1
    assert len(grouped([a, b], KITCHEN.table, gap=0.001)) == 2


def test_without_found_again_can_a_lone_views_can_is_told_by_its_colour():
    lower = Pose.from_xyz_yaw(0.43, -0.37, 0.176, 0.0)
    several = Detection("alphabet_soup", lower, 0.8, 5, 0.0, (), 0.830)
    again = Detection(
        "alphabet_soup", Pose.from_xyz_yaw(0.425, -0.38, 0.169, 0.0), 0.46, 1, 0.0, (), 0.835
    )
    assert apart([again, several], KITCHEN) == [several]
    assert apart([again, several], KITCHEN, found_again_can=False) == [again]


def test_without_rest_nothing_unseen_carries_and_nothing_inside_the_table_is_dropped():
    top = KITCHEN.object_types["butter"].size[2]
    butter = Pose.from_xyz_yaw(0.5, 0.0, top / 2)
    half = KITCHEN.object_types["tomato_soup"].size[2] / 2
    measured = Pose.from_xyz_yaw(0.5, 0.005, top + half - 0.003)
    can = Detection("tomato_soup", measured, 0.9, 3, 1.0, measured=measured)
    off = replace(SHIPPED, rest=False)
    (held,) = PoseEstimator.rest(KITCHEN, [can], [("butter", butter)])
    (fell,) = PoseEstimator.rest(KITCHEN, [can], [("butter", butter)], rules=off)
    assert held.pose.position[2] == pytest.approx(top + half)
    assert fell.pose.position[2] == pytest.approx(half)
    lying = replace(can, measured=Pose((0.5, 0.0, -0.15), (math.sqrt(0.5), 0, 0, math.sqrt(0.5))))
    assert PoseEstimator.rest(KITCHEN, [lying]) == []
    assert len(PoseEstimator.rest(KITCHEN, [lying], rules=off)) == 1


def test_near_ray_zero_leaves_a_lone_views_estimate_where_it_was_measured():
    seen = _seen(np.array([0.5, 0.0, 0.03]), 0, 0.9)
    ray = line_of_sight(seen)
    measured = Pose(tuple(ray[0] + 0.5 * ray[1]))
    before = Pose(tuple(ray[0] + 0.6 * ray[1] + [0.0, 0.0, 0.01]))
    assert along_ray_near(ray, measured, before) != measured
    assert along_ray_near(ray, measured, before, near=0.0) == measured


def test_lone_still_and_track_distance_bound_what_another_types_detection_may_be():
    last = {"butter": Pose.from_xyz_yaw(0.5, 0.0, 0.012)}
    lone = Detection("cream_cheese", Pose.from_xyz_yaw(0.6, 0.0, 0.012), 0.9, 1, 1.0)
    assert assign([lone], last, KITCHEN) == {}
    loose = replace(SHIPPED, lone_still=False)
    assert assigned([lone], last, KITCHEN, loose)["butter"] is lone
    both = replace(lone, views=2)
    assert assigned([both], last, KITCHEN)["butter"] is both
    assert assigned([both], last, KITCHEN, replace(SHIPPED, track_distance=0.05)) == {}
