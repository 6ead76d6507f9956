"""What a camera observer is given at a look, and what it gives back: the robot's side of
perception. Nothing here can reach the simulated scene (an import contract holds it): a
camera observer sees the world through these alone.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from hsgplan.domain.world import World
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.render import Camera


@dataclass(frozen=True)
class Seen:
    """An observer's view of the scene.

    Attributes:
        scene_graph: s_g as the agent gets it (objects never seen are not in it).
        unseen: objects whose pose was not observed this time (carried over from before).
        unknown: objects never seen yet: the agent has no pose for them.
        uncertain: objects whose believed pose is weak: not seen this time, or seen by a
            single view (its depth along that view's line of sight is what f_p gets worst).
        seconds: what making the belief cost (f_p and the tracker; rendering excluded).
    """

    scene_graph: GeometricSceneGraph
    unseen: tuple[str, ...] = ()
    unknown: tuple[str, ...] = ()
    uncertain: tuple[str, ...] = ()
    seconds: float = 0.0


@dataclass(frozen=True)
class Box:
    """An axis-aligned box in the world (m): where a part of the arm is, by the robot's own
    kinematics at its joints."""

    low: tuple[float, float, float]
    high: tuple[float, float, float]


@dataclass(frozen=True, eq=False)
class Look:
    """Everything a camera observer is given at one look: what a real robot has.

    Attributes:
        images: [V, H, W, 3] uint8, one per camera, rendered from the scene as it stands.
        cameras: the fixed cameras' calibration (pose and intrinsics), one per image.
        q: the arm's 7 joint values (its encoders).
        holding: the object the robot took up and has not let go, by its own record, if the
            gripper feels something between its fingers.
        held_pose: where that object is by the arm's kinematics and the grasp as planned.
        released: the object let go since the last look and where the hand let it go (the
            arm's kinematics and the grasp as planned), or pushed and where the push's stroke
            ended, if any.
        arm: the arm's links at `q`, as boxes by the robot's model of itself: what of the
            scene it may hide from a camera.
    """

    images: np.ndarray
    cameras: tuple[Camera, ...]
    q: np.ndarray
    holding: str | None = None
    held_pose: Pose | None = None
    released: tuple[str, Pose] | None = None
    arm: tuple[Box, ...] = ()


@runtime_checkable
class CameraObserver(Protocol):
    """An observer that owns its belief, built from looks alone."""

    name: str
    cameras: tuple[Camera, ...]

    def start(self, objects: tuple[str, ...], world: World) -> None:
        """A new episode: the goal's object names (their types follow from them), no poses,
        and the scene's world: its object types' sizes, its table and shelves (what a robot
        knows of its room and of the objects it handles)."""

    def look(self, look: Look) -> Seen: ...
