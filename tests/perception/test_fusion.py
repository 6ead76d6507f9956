"""Instances from several views grouped into objects by their lines of sight: each object
once with one instance per view, and a strong instance whose ray passes near another object's
does not take that object's instance from it."""

import numpy as np

from hsgplan.domain.kitchen import KITCHEN
from hsgplan.perception.fusion import (
    RAY_GAP,
    Seen,
    _gaps_within,
    grouped,
    line_of_sight,
    ray_gap,
)
from hsgplan.perception.keypoints import PinholeCamera
from hsgplan.perception.pnp import ViewKeypoints
from hsgplan.perception.vocabulary import kitchen_vocabulary

VIEWS = kitchen_vocabulary().views  # the shipped f_p's fixed cameras

CAMERAS = [PinholeCamera.of(c) for c in VIEWS]


def _seen(point, view: int, score: float, type_index: int = 0) -> Seen:
    camera = CAMERAS[view]
    pixels = np.full((9, 2), np.nan)
    pixels[-1] = camera.project(np.array([point]))[0]
    return Seen(type_index, score, view, ViewKeypoints(camera, pixels))


def test_two_objects_seen_by_three_views_are_two_groups_of_three():
    a, b = (0.45, 0.10, 0.03), (0.60, -0.15, 0.03)
    found = [_seen(p, v, 0.5 + 0.1 * v) for p in (a, b) for v in range(3)]
    groups = grouped(found, KITCHEN.table)
    assert len(groups) == 2
    for g in groups:
        assert sorted(s.view for s in g) == [0, 1, 2]
        object_of = {id(s): k // 3 for k, s in enumerate(found)}  # a's three views, then b's
        assert len({object_of[id(s)] for s in g}) == 1  # one object's instances
        assert [s.score for s in g] == sorted((s.score for s in g), reverse=True)


def test_a_strong_phantom_near_an_objects_line_of_sight_does_not_take_its_instance():
    real = np.array([0.50, 0.05, 0.03])
    origin, direction = line_of_sight(_seen(real, 1, 0.5))
    # a point on view 1's ray to the object, 8 cm farther along it and 1 cm to the side
    side = np.cross(direction, [0.0, 0.0, 1.0])
    ghost = origin + direction * (np.linalg.norm(real - origin) + 0.08)
    ghost = ghost + 0.01 * side / np.linalg.norm(side)
    phantom = _seen(ghost, 0, 0.9)  # stronger than anything else
    found = [phantom, _seen(real, 0, 0.6), _seen(real, 1, 0.5)]
    assert (
        ray_gap(phantom, found[2], KITCHEN.table) < RAY_GAP
    )  # the greedy rule would have paired them
    groups = grouped(found, KITCHEN.table)
    assert [len(g) for g in groups] == [1, 2]
    assert groups[0][0] is phantom
    assert {s.view for s in groups[1]} == {0, 1}


def test_instances_of_different_types_or_of_one_view_are_never_one_object():
    p = (0.45, 0.0, 0.03)
    assert [len(g) for g in grouped([_seen(p, 0, 0.9, 0), _seen(p, 1, 0.8, 1)], KITCHEN.table)] == [
        1,
        1,
    ]
    assert [len(g) for g in grouped([_seen(p, 0, 0.9), _seen(p, 0, 0.8)], KITCHEN.table)] == [1, 1]


def test_a_pair_of_rays_to_two_objects_does_not_break_up_an_object_every_view_saw():
    top = np.array([0.45, 0.25, 0.18])  # seen by all three views
    eye0, eye1 = CAMERAS[0].eye, CAMERAS[1].eye
    ghost = top + 0.1 * (eye0 - top) / np.linalg.norm(eye0 - top)  # on view 0's ray to it
    ray = (ghost - eye1) / np.linalg.norm(ghost - eye1)
    below = ghost + ray * 0.12  # another object, 12 cm on along view 1's ray through it

    def nudged(s: Seen, du: float) -> Seen:  # a pixel off: the object's own rays miss a little
        pixels = s.keypoints.pixels.copy()
        pixels[-1, 0] += du
        return Seen(s.type_index, s.score, s.view, ViewKeypoints(s.keypoints.camera, pixels))

    t0, t1, t2 = (
        _seen(top, 0, 0.9),
        nudged(_seen(top, 1, 0.8), 1.0),
        nudged(_seen(top, 2, 0.7), -1.0),
    )
    b1, b2 = _seen(below, 1, 0.6), _seen(below, 2, 0.5)
    assert (
        ray_gap(t0, b1, KITCHEN.table) < ray_gap(t0, t1, KITCHEN.table) < RAY_GAP
    )  # the closest pair is a ghost
    groups = grouped([t0, t1, t2, b1, b2], KITCHEN.table)
    assert [{id(s) for s in g} for g in groups] == [{id(t0), id(t1), id(t2)}, {id(b1), id(b2)}]


def test_every_pair_gap_at_once_is_each_pairs_ray_gap():
    # instances of two types at random points over and beside the table, in every view: the
    # pairs of one type in two views, within a gap wide enough to keep many, as one by one
    rng = np.random.default_rng(11)
    found = [
        _seen(rng.uniform((0.2, -0.5, 0.0), (0.8, 0.5, 0.4)), int(v), 0.5, int(k))
        for k in range(2)
        for v in rng.integers(0, len(CAMERAS), size=12)
    ]
    gap = 0.2
    expected = {
        (a, b): g
        for a in range(len(found))
        for b in range(a + 1, len(found))
        if found[a].view != found[b].view
        and found[a].type_index == found[b].type_index
        and (g := ray_gap(found[a], found[b], KITCHEN.table)) < gap
    }
    together = _gaps_within(found, KITCHEN.table, gap)
    assert len(expected) > 10
    assert together.keys() == expected.keys()
    assert all(abs(together[p] - g) < 1e-12 for p, g in expected.items())
