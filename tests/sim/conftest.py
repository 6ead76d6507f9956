"""The canonical scene of the simulation tests: four objects standing on the table."""

import pytest

from hsgplan.domain.kitchen import KITCHEN
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.scene import Scene


def standing(name, x, y, yaw=0.0, on_z=0.0):
    return Pose.from_xyz_yaw(x, y, on_z + KITCHEN.object_type(name).height / 2 + 0.001, yaw)


@pytest.fixture
def scene():
    s = Scene(
        ["cherries", "tomato_soup", "butter", "popcorn"],
        seed=0,
        poses={
            "cherries": standing("cherries", 0.42, 0.05),
            "butter": standing("butter", 0.55, -0.10),
            "popcorn": standing("popcorn", 0.36, -0.12),
            "tomato_soup": standing("tomato_soup", 0.305, 0.38),
        },
        world=KITCHEN,
    )
    s.settle()
    yield s
    s.close()
