"""The collision checker asks PyBullet about nearby pairs only: its verdicts must be those of
asking about every pair, with and without a held object, near contact included."""

import numpy as np
import pytest

from hsgplan.domain.parameters import PickParams
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.collision import SELF_PAIRS
from hsgplan.sim.primitives import execute
from hsgplan.sim.robot import HAND, REST, tilted, topdown


def _every_pair(checker, q) -> bool:
    """The verdict with no culling: every self pair, every obstacle, every link from 1."""
    robot, bc = checker.robot, checker.bc
    robot.set_q(q)
    arm, held = robot.body, robot.held_body
    if any(bc.getClosestPoints(arm, arm, 0.0, a, b) for a, b in SELF_PAIRS):
        return True
    for body in checker.obstacles:
        if any(pt[3] > 0 for pt in bc.getClosestPoints(arm, body, checker.margin)):
            return True
        if held is not None and bc.getClosestPoints(held, body, checker.margin):
            return True
    return False


def _configurations(scene, n=300):
    """Joints scattered around the rest pose, and joints that put the hand among the objects
    and shelves (the hand at random points low over the table): many touch, many are within
    centimetres, many are free."""
    rng = np.random.default_rng(5)
    robot = scene.robot
    qs = [np.clip(REST + rng.normal(0, 0.6, 7), robot.lower, robot.upper) for _ in range(n // 2)]
    while len(qs) < n:
        xyz = rng.uniform((0.25, -0.3, 0.0), (0.75, 0.5, 0.25))
        q = robot.ik(Pose(tuple(xyz), topdown(rng.uniform(-3, 3))), scene.rng, restarts=0)
        if q is not None:
            qs.append(q)
    return qs


def _mixed(verdicts) -> bool:
    hits = sum(a for a, _ in verdicts)
    return 0.15 * len(verdicts) < hits < 0.85 * len(verdicts)


@pytest.mark.parametrize("margin", [None, 0.0])
def test_verdicts_match_asking_every_pair(scene, margin):
    for ignore in ((), ("cherries",)):
        checker = scene.checker(ignore=ignore, margin=margin)
        verdicts = [(checker.collides(q), _every_pair(checker, q)) for q in _configurations(scene)]
        assert all(a == b for a, b in verdicts)
        assert _mixed(verdicts)  # both kinds were seen


def test_verdicts_match_with_a_held_object(scene):
    assert execute(scene, PickParams("cherries")).ok
    checker = scene.checker(ignore=("cherries",))
    verdicts = [(checker.collides(q), _every_pair(checker, q)) for q in _configurations(scene)]
    assert all(a == b for a, b in verdicts)
    assert _mixed(verdicts)


def _nearest(bc, body, obstacles, link=None) -> float:
    kw = {} if link is None else {"linkIndexA": link}
    d = [pt[8] for o in obstacles for pt in bc.getClosestPoints(body, o, 0.2, **kw)]
    return min(d, default=0.2)


def test_the_ghost_hand_is_where_the_real_one_is(scene):
    """At the pose the arm's TCP really reaches, the closed ghost hand and the arm's closed hand
    are as far from every obstacle (to a tenth of a millimetre), and touch the same things."""
    rng = np.random.default_rng(3)
    robot, bc = scene.robot, scene.bc
    hand, obstacles = scene.closed_hand(), scene.obstacles()
    robot.set_fingers(0.0)
    compared = touching = 0
    while compared < 60:
        xyz = rng.uniform((0.15, -0.3, 0.02), (0.7, 0.5, 0.2))
        pose = Pose(tuple(xyz), tilted(rng.uniform(-0.8, 0.8), rng.uniform(0.0, 1.2)))
        q = robot.ik(pose, scene.rng, restarts=0)
        if q is None:
            continue
        robot.set_q(q)
        tcp = robot.tcp()
        real = min(_nearest(bc, robot.body, obstacles, link) for link in HAND)
        bc.resetBasePositionAndOrientation(hand.body, tcp.position, tcp.orientation)
        ghost = _nearest(bc, hand.body, obstacles)
        assert abs(real - ghost) < 1e-4
        assert hand.touches([tcp], obstacles, 0.0) == (real <= 0.0)
        compared += 1
        touching += real <= 0.0
    assert 5 < touching < 55


def test_the_ghost_hand_asks_every_pose_until_one_touches(scene):
    """Several poses at once: a touch when any of them is within the margin of an obstacle
    (asked of every obstacle, no culling), none otherwise."""
    rng = np.random.default_rng(8)
    bc, hand, obstacles = scene.bc, scene.closed_hand(), scene.obstacles()
    margin = 0.01
    verdicts = []
    for _ in range(40):
        poses = [
            Pose(
                tuple(rng.uniform((0.15, -0.3, 0.02), (0.7, 0.5, 0.2))),
                tilted(rng.uniform(-0.8, 0.8), rng.uniform(0.0, 1.2)),
            )
            for _ in range(3)
        ]
        expected = False
        for pose in poses:
            bc.resetBasePositionAndOrientation(hand.body, pose.position, pose.orientation)
            expected |= _nearest(bc, hand.body, obstacles) < margin
        verdicts.append(expected)
        assert hand.touches(poses, obstacles, margin) == expected
    assert 5 < sum(verdicts) < 35
