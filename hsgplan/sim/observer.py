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

from typing import Protocol

from hsgplan.sim.scene import Scene
from hsgplan.sim.sensing import CameraObserver, Look, Seen

__all__ = ["CameraObserver", "GroundTruth", "Look", "SceneObserver", "Seen"]


class SceneObserver(Protocol):
    name: str

    def reset(self, scene: Scene) -> None:
        """A new episode's scene, before its first observation."""

    def observe(self, scene: Scene) -> Seen: ...


class GroundTruth:
    """s_g from the simulator's poses."""

    name = "gt"

    def reset(self, scene: Scene) -> None:
        pass

    def observe(self, scene: Scene) -> Seen:
        return Seen(scene.scene_graph())
