"""What the agent sees of the scene (f_p): a `SceneObserver` turns the simulated scene into the
geometric scene graph the agent plans on. The ground truth reads the simulator's poses; an
observer from camera images (`perception.observer.RgbObserver`) plugs in the same way, and the
env keeps the truth beside it to judge the episode.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.sim.scene import Scene


@dataclass(frozen=True)
class Seen:
    """An observer's view of the scene.

    Attributes:
        scene_graph: s_g as the agent gets it.
        unseen: objects whose pose was not observed this time (carried over from before).
    """

    scene_graph: GeometricSceneGraph
    unseen: tuple[str, ...] = ()


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
