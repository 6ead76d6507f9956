"""A scene without the arm's visual meshes behaves as the one with them: only pictures differ."""

from pathlib import Path

import numpy as np

from hsgplan.domain.goals import parse_goal
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.parameters import PickParams
from hsgplan.sim.env import KitchenStorageEnv
from hsgplan.sim.outcome import Status
from hsgplan.sim.primitives import execute
from hsgplan.sim.robot import panda_urdf
from hsgplan.sim.scene import Scene

from .conftest import standing

CAN = "tomato_soup"


def test_the_copy_without_visuals_keeps_every_link_and_collision_shape_and_no_visual():
    text = Path(panda_urdf(visuals=False)).read_text()
    original = Path(panda_urdf()).read_text()
    assert "<visual>" in original and "<visual>" not in text
    assert text.count("<collision>") == original.count("<collision>") > 0
    assert text.count("<link ") == original.count("<link ") and "package://" not in text
    assert panda_urdf(visuals=False) == panda_urdf(visuals=False)  # written once


def test_a_pick_runs_the_same_with_and_without_visuals():
    ends = []
    for visuals in (True, False):
        poses = {CAN: standing(CAN, 0.5, 0.05)}
        with Scene((CAN,), seed=3, poses=poses, visuals=visuals, world=KITCHEN) as scene:
            scene.settle()
            outcome = execute(scene, PickParams(CAN))
            ends.append((outcome.status, scene.robot.q(), scene.pose(CAN).position))
    (s1, q1, p1), (s2, q2, p2) = ends
    assert s1 == s2 == Status.SUCCESS and np.array_equal(q1, q2) and p1 == p2


def test_an_env_nothing_pictures_resets_without_visuals_and_a_rendering_one_with_them():
    goal = parse_goal("In(cherries, shelf_a)", world=KITCHEN)
    quiet, rendering = (
        KitchenStorageEnv(visuals=False, world=KITCHEN),
        KitchenStorageEnv(render=True, world=KITCHEN),
    )
    try:
        for env in (quiet, rendering):
            env.reset(seed=1, options={"goal": goal})
        assert not quiet.visuals and rendering.visuals
        meshes = [
            [s[4] for s in env.scene.bc.getVisualShapeData(env.scene.robot.body)]
            for env in (quiet, rendering)
        ]
        # without its visual meshes PyBullet pictures a link by its collision shape
        assert all(b"/collision/" in m for m in meshes[0])
        assert any(b"/visual/" in m for m in meshes[1])
        assert quiet.scene.poses() == rendering.scene.poses()
    finally:
        quiet.close()
        rendering.close()
