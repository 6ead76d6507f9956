"""A drawn start scene where no grasp fits an object (its neighbours too close for the open
fingers) is mended by putting that object on another free spot of its surface, the rest of the
draw kept; without the mending the whole draw is given up."""

from __future__ import annotations

import random

from hsgplan.domain.kitchen import KITCHEN
from hsgplan.sim import sampler
from hsgplan.sim.sampler import sample_scene

OBJECTS = ("butter", "cream_cheese", "cherries", "popcorn")


def test_an_object_no_grasp_fits_is_put_elsewhere_and_the_rest_of_the_draw_kept(monkeypatch):
    scene, state = sample_scene(OBJECTS, seed=3, world=KITCHEN)
    try:
        stuck = next(o for o in OBJECTS if sampler._movable(scene, state, o))
        where = {o: scene.pose(o) for o in OBJECTS}

        def graspable(scene, state, obj):  # no grasp fits `stuck` where it was drawn
            return obj != stuck or scene.pose(obj).distance(where[stuck]) > 0.005

        monkeypatch.setattr(sampler, "_graspable", graspable)
        assert sampler._settled_as(scene, state, random.Random(0))
        assert scene.pose(stuck).distance(where[stuck]) > 0.005
        assert all(scene.pose(o).distance(where[o]) < 0.005 for o in OBJECTS if o != stuck)

        for o, pose in where.items():  # the draw as it was, with no mending allowed
            scene.set_pose(o, pose)
        assert not sampler._settled_as(scene, state, random.Random(0), repairs=0)
    finally:
        scene.close()
