"""Estimates made to rest: a slightly tilted, floating or sunk estimate lands upright on the
support beneath it, stacks bottom first; one far from every support is left alone."""

import math

import numpy as np
import pytest

from hsgplan.domain.objects import object_type
from hsgplan.domain.world import SHELF_TOP_Z
from hsgplan.perception.settle import settle, upright
from hsgplan.scene_graph.geometry import Pose, matrix_to_quat


def _tilted(x, y, z, yaw, tilt) -> Pose:
    c, s = math.cos(yaw), math.sin(yaw)
    rz = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])
    rx = np.array(
        [[1, 0, 0], [0, math.cos(tilt), -math.sin(tilt)], [0, math.sin(tilt), math.cos(tilt)]]
    )
    return Pose((x, y, z), matrix_to_quat(rz @ rx))


def _half(t: str) -> float:
    return object_type(t).size[2] / 2


def test_a_tilted_estimate_is_turned_upright_keeping_its_yaw_and_upside_down_counts_as_up():
    p = upright(_tilted(0.5, 0.0, 0.05, 0.4, math.radians(8)))
    assert p.rotation[2, 2] == pytest.approx(1.0)
    assert math.atan2(p.rotation[1, 0], p.rotation[0, 0]) == pytest.approx(0.4, abs=1e-6)
    flipped = upright(_tilted(0.5, 0.0, 0.05, 0.4, math.pi - math.radians(5)))
    assert flipped.rotation[2, 2] == pytest.approx(1.0)
    lying = _tilted(0.5, 0.0, 0.05, 0.4, math.radians(80))
    assert upright(lying) == lying


def test_a_stack_lands_bottom_first_and_a_shelf_top_holds_what_is_near_it():
    types = ["cherries", "butter", "tomato_soup", "popcorn"]
    poses = [
        _tilted(0.5, 0.0, 2 * _half("butter") + _half("cherries") + 0.012, 0.0, 0.05),  # on butter
        _tilted(0.5, 0.005, _half("butter") - 0.008, 0.3, 0.02),  # sunk into the table
        _tilted(0.49, 0.38, SHELF_TOP_Z + _half("tomato_soup") + 0.015, 0.0, 0.0),  # shelf top
        _tilted(0.3, -0.1, _half("popcorn") + 0.2, 0.0, 0.0),  # in the air: nothing near
    ]
    out = settle(types, poses)
    assert out[1].position[2] == pytest.approx(_half("butter"))
    assert out[0].position[2] == pytest.approx(2 * _half("butter") + _half("cherries"))
    assert out[2].position[2] == pytest.approx(SHELF_TOP_Z + _half("tomato_soup"))
    assert out[3].position == poses[3].position
