"""Trying primitives in the episode's world and taking them back: the model a search-based
planner checks its plans in (the world's own physics and geometry, as PDDLStream checks its
plans in PyBullet with the poses it knows).

A `Lookahead` is also a feasibility check (a dry run of one primitive), so it goes wherever
one is expected; agents that plan ahead open a `Trial` on it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

from hsgplan.domain.parameters import PrimitiveParams
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.sim.outcome import Outcome
from hsgplan.sim.primitives import execute
from hsgplan.sim.scene import Scene


@dataclass(frozen=True)
class Mark:
    """A point a trial can go back to: the physics state, the grasp (a constraint, which a
    saved state leaves out) and the random state that motion planning draws from."""

    state: int
    grip: tuple[int | None, bool]  # `Panda.grip`
    rng: dict[str, Any]


class Trial:
    """Primitives run for real in the scene, every one of them undone when the trial closes.

    Args:
        scene: the episode's scene; it is back as it was (random state included, so that
            the primitive executed next plans as it would have) once `close` returns.
    """

    def __init__(self, scene: Scene) -> None:
        self.scene = scene
        # bodies made on first use (the closed hand of a push) must exist before any state
        # is saved: PyBullet restores a state only into the same set of bodies
        scene.closed_hand()
        self._marks: list[Mark] = []
        self._start = self.mark()

    def mark(self) -> Mark:
        m = Mark(
            self.scene.snapshot(),
            self.scene.robot.grip(),
            self.scene.rng.bit_generator.state,
        )
        self._marks.append(m)
        return m

    def back(self, mark: Mark) -> None:
        self.scene.back_to(mark.state, mark.grip)
        self.scene.rng.bit_generator.state = mark.rng

    def run(self, params: PrimitiveParams) -> Outcome:
        return execute(self.scene, params)

    def scene_graph(self) -> GeometricSceneGraph:
        return self.scene.scene_graph()

    def close(self) -> None:
        self.back(self._start)
        for m in self._marks:
            self.scene.bc.removeState(m.state)
        self._marks.clear()


class Lookahead:
    """The current scene of an episode, for dry runs and trials.

    Args:
        scene: gives the episode's scene as it is now (a new one after every reset).
        check: the dry run of one primitive (`KitchenStorageEnv.check`).
    """

    def __init__(self, scene: Callable[[], Scene], check: Callable[[PrimitiveParams], bool]):
        self._scene = scene
        self._check = check

    def __call__(self, params: PrimitiveParams) -> bool:
        return self._check(params)

    @contextmanager
    def trial(self) -> Iterator[Trial]:
        t = Trial(self._scene())
        try:
            yield t
        finally:
            t.close()
