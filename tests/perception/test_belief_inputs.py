"""Seeing through f_p, the belief is built from looks alone: what a look carries, and that no
import reaches the simulated scene from the observer's side."""

import dataclasses
import typing

import grimp
import numpy as np

from hsgplan.domain.world import World
from hsgplan.perception.observer import RgbObserver
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.render import Camera
from hsgplan.sim.sensing import Box, CameraObserver, Look

BELIEF_SIDE = (
    "hsgplan.perception.observer",
    "hsgplan.perception.estimator",
    "hsgplan.sim.sensing",
)
SIMULATOR = ("hsgplan.sim.scene", "hsgplan.sim.env", "hsgplan.sim.robot", "hsgplan.sim.staging")


def test_a_look_carries_images_calibration_joints_and_the_hands_own_record_only():
    hints = typing.get_type_hints(Look)
    allowed = {
        np.ndarray,
        tuple[Camera, ...],
        str | None,
        Pose | None,
        tuple[str, Pose] | None,
        tuple[Box, ...],
    }
    assert [f.name for f in dataclasses.fields(Look)] == [
        "images",
        "cameras",
        "q",
        "holding",
        "held_pose",
        "released",
        "arm",
    ]
    assert set(hints.values()) <= allowed, hints


def test_the_observer_is_given_looks_object_names_and_its_world_nothing_else():
    assert isinstance(RgbObserver(estimator=None, cameras=()), CameraObserver)
    assert list(typing.get_type_hints(RgbObserver.look)) == ["look", "return"]
    assert typing.get_type_hints(RgbObserver.start) == {
        "objects": tuple[str, ...],
        "world": World,
        "return": type(None),
    }
    assert not hasattr(RgbObserver, "observe") and not hasattr(RgbObserver, "reset")


def test_no_import_chain_leads_from_the_belief_to_the_simulated_scene():
    graph = grimp.build_graph("hsgplan")
    for source in BELIEF_SIDE:
        for sim in SIMULATOR:
            chain = graph.find_shortest_chain(importer=source, imported=sim)
            assert chain is None, chain
