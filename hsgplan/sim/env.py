"""`KitchenStorageEnv`: the world as a Gymnasium env (`gymnasium.make(ENV_ID)`).

Actions are parametrised primitives: the `Dict` of `Discrete`s in `gym_spaces`, or the typed
`PickParams`, `PlaceParams`, `PushParams` the agents use. Observations are numeric for
Gymnasium; the typed one (the geometric scene graph, its symbols and, when rendering is on, an
RGB image from the fixed camera) is in `info["observation"]`: what the env's observer
(`sim.observer`, the ground truth by default) makes of the scene, with the true symbols beside
it to judge by. The reward is 1 on the step where the goal truly holds.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import gymnasium
import numpy as np

from hsgplan.domain.goals import Goal, parse_goal
from hsgplan.domain.parameters import PrimitiveParams
from hsgplan.domain.world import MAX_STEPS
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.symbol_mapping import SymbolMapping, map_symbols
from hsgplan.sim.gym_spaces import action_space, decode, encode, observation_space
from hsgplan.sim.lookahead import Lookahead
from hsgplan.sim.motion_plans import MotionPlan, PlanFailure, plan_primitive
from hsgplan.sim.observer import GroundTruth, SceneObserver
from hsgplan.sim.outcome import Outcome, Status
from hsgplan.sim.primitives import execute
from hsgplan.sim.render import Camera
from hsgplan.sim.sampler import sample_scene
from hsgplan.sim.scene import Scene
from hsgplan.symbolic.generator import check_size, random_goals

ENV_ID = "hsgplan/KitchenStorage-v0"


@dataclass(frozen=True)
class Observation:
    """What the agent gets (`scene_graph`, `symbols`: the observer's), and the truth.

    Attributes:
        true_symbols: f_m of the simulator's poses; the same object as `symbols` when the
            observer is the ground truth.
        unseen: objects the observer did not see this time (their poses carried over).
    """

    scene_graph: GeometricSceneGraph
    symbols: SymbolMapping
    rgb: np.ndarray | None
    true_symbols: SymbolMapping
    unseen: tuple[str, ...] = ()


@dataclass(frozen=True)
class ResetOptions:
    """What an episode is about: the goal (the scene holds exactly its objects)."""

    goal: Goal
    p_elsewhere: float = 0.3


class KitchenStorageEnv(gymnasium.Env):
    """One episode at a time; `reset` builds a fresh scene from the seed.

    The Gymnasium observation is numeric (`gym_spaces.observation_space`); the typed one the
    agents read (`Observation`: the scene graphs) is `info["observation"]`. `step` takes an
    action of `action_space` or a typed `PrimitiveParams`.

    Args:
        render: put an RGB image in every typed observation.
        camera: the fixed camera used for images.
        max_steps: after this many primitives an episode is truncated.
        objects: the size of the random goal drawn when `reset` is given none.
        render_mode: "rgb_array" (what `render()` returns) or None.
        observer: what the agent sees of the scene (default: the ground truth).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 4}

    def __init__(
        self,
        render: bool = False,
        camera: Camera | None = None,
        max_steps: int = MAX_STEPS,
        objects: int = 3,
        render_mode: str | None = None,
        observer: SceneObserver | None = None,
    ):
        if render_mode not in (None, *self.metadata["render_modes"]):
            raise ValueError(f"render_mode {render_mode!r}: None or 'rgb_array'")
        check_size(objects)  # refused here, not at the first reset
        self.render_mode = render_mode
        self.observation_space = observation_space()
        self.action_space = action_space()
        self.render_images = render
        self.camera = camera or Camera()
        self.max_steps = max_steps
        self.objects = objects
        self.observer = observer or GroundTruth()
        self.scene: Scene | None = None
        self.goal: Goal | None = None
        self.steps = 0
        self._checked: dict[PrimitiveParams, tuple[MotionPlan, float]] = {}
        # dry runs (as a feasibility check) and trials of whole plans, for agents that look ahead
        self.lookahead = Lookahead(lambda: self.scene, self.check)

    def reset(
        self, *, seed: int | None = None, options: ResetOptions | dict | None = None
    ) -> tuple[dict, dict]:
        """A fresh scene. With a seed, the scene is that seed's (the same seed, the same
        episode); without one it is drawn from `np_random`. `options`: a `ResetOptions`, or
        `{"goal": Goal or goal text, "p_elsewhere": float}`, or None for a random goal of
        `objects` objects drawn from the scene's seed."""
        super().reset(seed=seed)
        scene_seed = seed if seed is not None else int(self.np_random.integers(2**31))
        options = _options(options, self.objects, scene_seed)
        self.close()
        self.goal = options.goal
        self.scene, _ = sample_scene(options.goal.objects, scene_seed, options.p_elsewhere)
        self.steps = 0
        self._checked.clear()
        self.observer.reset(self.scene)
        typed = self._observe()
        return self._encode(typed), {"seed": scene_seed, "observation": typed}

    def step(
        self, action: PrimitiveParams | dict, on_frame: Callable[[], None] | None = None
    ) -> tuple[dict, float, bool, bool, dict]:
        if self.scene is None or self.goal is None:
            raise RuntimeError("call reset() before step()")
        params = (
            action if isinstance(action, PrimitiveParams) else decode(self.goal.objects, action)
        )
        if isinstance(params, str):  # nothing to execute: a step spent, nothing moved
            outcome = Outcome(Status.INVALID, params, 0.0)
        else:
            plan, plan_seconds = self._checked.get(params, (None, 0.0))
            outcome = execute(self.scene, params, on_frame, plan)
            # A plan from a dry run is part of this primitive's cost: its time is added back.
            outcome = Outcome(outcome.status, outcome.detail, outcome.seconds + plan_seconds)
        self._checked.clear()
        self.steps += 1
        typed = self._observe()
        done = self.goal.satisfied_by(typed.true_symbols.state)
        truncated = not done and self.steps >= self.max_steps
        info = {"outcome": outcome, "observation": typed}
        return self._encode(typed), float(done), done, truncated, info

    def check(self, action: PrimitiveParams) -> bool:
        """A dry run: whether the primitive can be planned in the scene as it is. Nothing
        moves, no step is spent, and a following `step` with the same action reuses the plan."""
        start = time.perf_counter()
        plan = plan_primitive(self.scene, action)
        if isinstance(plan, PlanFailure):
            return False
        self._checked[action] = (plan, time.perf_counter() - start)
        return True

    def render(self, camera: Camera | None = None) -> np.ndarray | None:
        """An RGB image from `camera` (default: the env's fixed camera)."""
        if self.scene is None:
            raise RuntimeError("call reset() before render()")
        return (camera or self.camera).capture(self.scene.bc)

    def close(self) -> None:
        if self.scene is not None:
            self.scene.close()
            self.scene = None

    def _observe(self) -> Observation:
        seen = self.observer.observe(self.scene)
        rgb = self.render() if self.render_images else None
        symbols = map_symbols(seen.scene_graph)
        if isinstance(self.observer, GroundTruth):  # what it sees is the truth: mapped once
            true_symbols = symbols
        else:
            true_symbols = map_symbols(self.scene.scene_graph())
        return Observation(seen.scene_graph, symbols, rgb, true_symbols, seen.unseen)

    def _encode(self, typed: Observation) -> dict:
        return encode(self.goal.objects, typed.scene_graph, typed.symbols.state)


def _options(options: ResetOptions | dict | None, objects: int, seed: int) -> ResetOptions:
    if isinstance(options, ResetOptions):
        return options
    options = options or {}
    goal = options.get("goal")
    if goal is None:
        goal = random_goals(objects, 1, seed)[0]
    if isinstance(goal, str):
        goal = parse_goal(goal)
    if not isinstance(goal, Goal):
        raise ValueError("options['goal']: a Goal or goal text")
    return ResetOptions(goal, float(options.get("p_elsewhere", ResetOptions.p_elsewhere)))


gymnasium.register(id=ENV_ID, entry_point="hsgplan.sim.env:KitchenStorageEnv")
