"""`KitchenStorageEnv`: the world behind a Gymnasium-style interface.

Actions are parametrised primitives (`PickParams`, `PlaceParams`, `PushParams`); observations
carry the geometric scene graph and, when rendering is on, an RGB image from the fixed camera.
The reward is 1 on the step where the goal first holds.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from hsgplan.domain.goals import Goal
from hsgplan.domain.parameters import PrimitiveParams
from hsgplan.domain.world import MAX_STEPS
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.symbol_mapping import SymbolMapping, map_symbols
from hsgplan.sim.lookahead import Lookahead
from hsgplan.sim.motion_plans import MotionPlan, PlanFailure, plan_primitive
from hsgplan.sim.outcome import Outcome
from hsgplan.sim.primitives import execute
from hsgplan.sim.render import Camera
from hsgplan.sim.sampler import sample_scene
from hsgplan.sim.scene import Scene


@dataclass(frozen=True)
class Observation:
    scene_graph: GeometricSceneGraph
    symbols: SymbolMapping
    rgb: np.ndarray | None


@dataclass(frozen=True)
class ResetOptions:
    """What an episode is about: the goal (the scene holds exactly its objects)."""

    goal: Goal
    p_elsewhere: float = 0.3


class KitchenStorageEnv:
    """One episode at a time; `reset` builds a fresh scene from the seed.

    Args:
        render: put an RGB image in every observation.
        camera: the fixed camera used for images.
        max_steps: after this many primitives an episode is truncated.
    """

    def __init__(
        self, render: bool = False, camera: Camera | None = None, max_steps: int = MAX_STEPS
    ):
        self.render_images = render
        self.camera = camera or Camera()
        self.max_steps = max_steps
        self.scene: Scene | None = None
        self.goal: Goal | None = None
        self.steps = 0
        self._checked: dict[PrimitiveParams, tuple[MotionPlan, float]] = {}
        # dry runs (as a feasibility check) and trials of whole plans, for agents that look ahead
        self.lookahead = Lookahead(lambda: self.scene, self.check)

    def reset(self, seed: int, options: ResetOptions) -> tuple[Observation, dict]:
        self.close()
        self.goal = options.goal
        self.scene, _ = sample_scene(options.goal.objects, seed, options.p_elsewhere)
        self.steps = 0
        self._checked.clear()
        return self._observe(), {"seed": seed}

    def step(
        self, action: PrimitiveParams, on_frame: Callable[[], None] | None = None
    ) -> tuple[Observation, float, bool, bool, dict]:
        if self.scene is None or self.goal is None:
            raise RuntimeError("call reset() before step()")
        plan, plan_seconds = self._checked.get(action, (None, 0.0))
        outcome: Outcome = execute(self.scene, action, on_frame, plan)
        # A plan from a dry run is part of this primitive's cost: its time is added back.
        outcome = Outcome(outcome.status, outcome.detail, outcome.seconds + plan_seconds)
        self._checked.clear()
        self.steps += 1
        obs = self._observe()
        done = self.goal.satisfied_by(obs.symbols.state)
        truncated = not done and self.steps >= self.max_steps
        return obs, float(done), done, truncated, {"outcome": outcome}

    def check(self, action: PrimitiveParams) -> bool:
        """A dry run: whether the primitive can be planned in the scene as it is. Nothing
        moves, no step is spent, and a following `step` with the same action reuses the plan."""
        start = time.perf_counter()
        plan = plan_primitive(self.scene, action)
        if isinstance(plan, PlanFailure):
            return False
        self._checked[action] = (plan, time.perf_counter() - start)
        return True

    def render(self, camera: Camera | None = None) -> np.ndarray:
        """An RGB image from `camera` (default: the env's fixed camera)."""
        if self.scene is None:
            raise RuntimeError("call reset() before render()")
        return (camera or self.camera).capture(self.scene.bc)

    def close(self) -> None:
        if self.scene is not None:
            self.scene.close()
            self.scene = None

    def _observe(self) -> Observation:
        sg = self.scene.scene_graph()
        return Observation(sg, map_symbols(sg), self.render() if self.render_images else None)
