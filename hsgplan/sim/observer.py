"""What the agent sees of the scene (f_p), and what it is given to see with.

Two kinds of observer plug into the env:

- a `SceneObserver` reads the simulated `Scene` itself: the ground truth (`GroundTruth`), or a
  test's stand-in. The robot then plans its motions in the simulated scene, whose poses are
  what it sees.
- a `CameraObserver` is given a `Look` and nothing else: the fixed cameras' images and
  calibration, the arm's joints and what the robot knows of its own hand. It owns the belief
  (poses and how sure it is of each), and the env plans every motion in a model of that
  belief (`sim.belief_world`), never in the simulated scene: f_p on the cameras
  (`perception.observer.RgbObserver`) is one.

The env keeps the truth beside either, to judge the episode at its end.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.render import Camera
from hsgplan.sim.scene import Scene


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
            arm's kinematics and the grasp as planned), if any.
    """

    images: np.ndarray
    cameras: tuple[Camera, ...]
    q: np.ndarray
    holding: str | None = None
    held_pose: Pose | None = None
    released: tuple[str, Pose] | None = None


class SceneObserver(Protocol):
    name: str

    def reset(self, scene: Scene) -> None:
        """A new episode's scene, before its first observation."""

    def observe(self, scene: Scene) -> Seen: ...


@runtime_checkable
class CameraObserver(Protocol):
    """An observer that owns its belief, built from looks alone."""

    name: str
    cameras: tuple[Camera, ...]

    def start(self, objects: tuple[str, ...]) -> None:
        """A new episode: the goal's object names (their types follow from them), no poses."""

    def look(self, look: Look) -> Seen: ...


class GroundTruth:
    """s_g from the simulator's poses."""

    name = "gt"

    def reset(self, scene: Scene) -> None:
        pass

    def observe(self, scene: Scene) -> Seen:
        return Seen(scene.scene_graph())
