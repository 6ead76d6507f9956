"""`KitchenStorageEnv`: the world as a Gymnasium env (`gymnasium.make(ENV_ID)`).

Actions are parametrised primitives: the `Dict` of `Discrete`s in `gym_spaces`, or the typed
`PickParams`, `PlaceParams`, `PushParams` the agents use. Observations are numeric for
Gymnasium; the typed one (the geometric scene graph, its symbols and, when rendering is on, an
RGB image from the fixed camera) is in `info["observation"]`: what the env's observer
(`sim.observer`, the ground truth by default) makes of the scene, with the true symbols beside
it to judge by. The reward is 1, and the episode terminates, on the step where the goal holds
in what the observer sees (with a camera observer, the robot's belief); whether it truly
holds is `info["goal_truly_holds"]`, what a step truly moved besides its object is
`info["disturbed"]`, and the one judge's verdict on the step, on the simulator's state, is
`info["verdict"]` (`sim.outcome.judge`), kept for the episode's record in `verdicts`: under the
ground truth it is the step's outcome; seeing through cameras the robot reads its own.

With a camera observer (`sim.sensing.CameraObserver`) the robot knows only its belief: every
primitive is planned in the model of that belief (`sim.belief_world`) and the simulated scene
runs its joint motions; a step's outcome is judged on what the gripper feels and on the belief
before and after it (a new look), and before acting on an object the belief is unsure of the
arm moves out of the cameras' way and looks again (`relook`): `sim/believing.py`.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import gymnasium
import numpy as np

from hsgplan.domain.goals import Goal
from hsgplan.domain.parameters import PrimitiveParams
from hsgplan.domain.recovery import ALL_RULES, RecoveryRules
from hsgplan.domain.scene import World
from hsgplan.domain.world import MAX_STEPS
from hsgplan.scene_graph.symbol_mapping import map_symbols
from hsgplan.sim.belief_world import BeliefWorld
from hsgplan.sim.believing import BelievedSteps, sure_in_both
from hsgplan.sim.env_types import Observation, ResetOptions, reset_options
from hsgplan.sim.gym_spaces import action_space, decode, encode, observation_space
from hsgplan.sim.lookahead import Lookahead
from hsgplan.sim.motion_plans import MotionPlan, PlanFailure, plan_primitive
from hsgplan.sim.observer import CameraObserver, GroundTruth, SceneObserver, Seen
from hsgplan.sim.outcome import (
    Outcome,
    Status,
    Verdict,
    belief_errors,
    disturbances,
    dragged,
    judge,
    largest_move,
)
from hsgplan.sim.plan_rules import SHIPPED as PLAN_RULES
from hsgplan.sim.plan_rules import PlanRules
from hsgplan.sim.primitives import execute
from hsgplan.sim.render import Camera
from hsgplan.sim.sampler import sample_scene
from hsgplan.sim.scene import Scene
from hsgplan.symbolic.generator import check_size

ENV_ID = "hsgplan/KitchenStorage-v0"


class KitchenStorageEnv(BelievedSteps, gymnasium.Env):
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
        observer: what the agent sees of the scene (default: the ground truth); a camera
            observer makes the robot act on its belief (see the module).
        rules: the rules in force; the env reads the perception rules (`PERCEPTION_RULES`:
            `relook`, `relook_failed`, `near_moves_only`, `seek_unseen`), which act only with a
            camera observer (`hsgplan.domain.recovery` documents each).
        visuals: load the arm's visual meshes, for pictures of the scene (rendering, a camera
            observer, a demo's frames); an env nothing pictures resets faster without them,
            and runs the same episodes.
        world: the world of the random goals `reset` draws and of goal texts it is given; an
            episode's world is its goal's (`Goal.world`).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 4}

    def __init__(
        self,
        render: bool = False,
        camera: Camera | None = None,
        max_steps: int = MAX_STEPS,
        objects: int = 3,
        render_mode: str | None = None,
        observer: SceneObserver | CameraObserver | None = None,
        rules: RecoveryRules = ALL_RULES,
        visuals: bool = True,
        plan_rules: PlanRules = PLAN_RULES,
        *,
        world: World,
    ):
        self.scene_world = world
        self.plan_rules = plan_rules  # the motion planner's, in the scene and in the model
        if render_mode not in (None, *self.metadata["render_modes"]):
            raise ValueError(f"render_mode {render_mode!r}: None or 'rgb_array'")
        check_size(objects)  # refused here, not at the first reset
        self.render_mode = render_mode
        self.observation_space = observation_space(world)
        self.action_space = action_space(world)
        self.render_images = render
        self.camera = camera or Camera()
        self.max_steps = max_steps
        self.objects = objects
        self.observer = observer or GroundTruth()
        self.believing = isinstance(self.observer, CameraObserver)
        self.rules = rules
        self.visuals = visuals or render or render_mode is not None or self.believing
        self.world: BeliefWorld | None = None  # the robot's model (made at reset)
        self._seen: Seen | None = None  # the belief's last look
        self._judged: Seen | None = None  # the look that judged the last step, if one did
        self._released = None
        self._judged_from: Seen | Observation | None = None  # the last observation
        self.scene: Scene | None = None
        self.goal: Goal | None = None
        self.steps = 0
        # the last step's plan, if one was made (for recordings of the episode)
        self.last_plan: MotionPlan | None = None
        # dry runs' plans, each with the state of the scene it was made in (`_state`)
        self._checked: dict[PrimitiveParams, tuple[MotionPlan, float, tuple]] = {}
        # the judge's verdict on each step of the episode, on the simulator's state: the
        # record's, which no decision reads
        self.verdicts: list[Verdict] = []
        self._stopped: str | None = None
        # dry runs that found no plan, with the state they were made in: asked again there,
        # the answer is the same
        self._unplannable: set[tuple[PrimitiveParams, tuple]] = set()
        # dry runs (as a feasibility check) and trials of whole plans, for agents that look ahead
        self.lookahead = Lookahead(self._planning_scene, self.check)

    def reset(
        self, *, seed: int | None = None, options: ResetOptions | dict | None = None
    ) -> tuple[dict, dict]:
        """A fresh scene. With a seed, the scene is that seed's (the same seed, the same
        episode); without one it is drawn from `np_random`. `options`: a `ResetOptions`, or
        `{"goal": Goal or goal text, "p_elsewhere": float}`, or None for a random goal of
        `objects` objects drawn from the scene's seed."""
        super().reset(seed=seed)
        scene_seed = seed if seed is not None else int(self.np_random.integers(2**31))
        options = reset_options(options, self.objects, scene_seed, self.scene_world)
        if options.goal.world.entity_types != self.scene_world.entity_types:
            raise ValueError("the goal names another world's objects than the env's spaces hold")
        self.close()
        self.goal = options.goal
        self.scene, _ = sample_scene(
            options.objects(),
            scene_seed,
            options.p_elsewhere,
            self.visuals,
            world=options.goal.world,
        )
        self.steps = 0
        self.verdicts = []
        self._checked.clear()
        self._unplannable.clear()
        self._seen = self._judged = self._released = None
        # the robot's model, where it plans, dry-runs and tries: of its belief seeing through
        # cameras, of the truth under the ground truth (`_observe` puts it right)
        self.world = BeliefWorld(options.objects(), scene_seed, options.goal.world)
        self.scene.plan_rules = self.world.scene.plan_rules = self.plan_rules
        if self.believing:
            self.observer.start(options.objects(), options.goal.world)
        else:
            self.observer.reset(self.scene)
        typed = self._observe()
        return self._encode(typed), {"seed": scene_seed, "observation": typed}

    def step(
        self, action: PrimitiveParams | dict, on_frame: Callable[[], None] | None = None
    ) -> tuple[dict, float, bool, bool, dict]:
        if self.scene is None or self.goal is None:
            raise RuntimeError("call reset() before step()")
        params = (
            action
            if isinstance(action, PrimitiveParams)
            else decode(self.scene.objects, action, self.scene.world)
        )
        truth_before = self.scene.scene_graph()
        true_before = {n.name: n.pose for n in truth_before.nodes}
        self.last_plan = None
        self._stopped = None
        phases: list[tuple[str, dict]] = []  # the record's: where each phase left the objects

        def ended(name: str) -> None:
            phases.append((name, self.scene.poses()))

        if isinstance(params, str):  # nothing to execute: a step spent, nothing moved
            outcome = Outcome(Status.INVALID, params, 0.0)
        elif self.believing:
            outcome = self._step_believed(params, on_frame, ended)
        else:
            plan, plan_seconds = self._checked_plan(params)
            if plan is None:  # planned in the model, which `_observe` put to the truth
                start = time.perf_counter()
                plan = self.world.plan(params)
                plan_seconds = time.perf_counter() - start
            if isinstance(plan, MotionPlan):
                self.last_plan = plan
            outcome = execute(self.scene, params, on_frame, plan, ended)
            # The plan is part of this primitive's cost: its time is added back.
            outcome = Outcome(outcome.status, outcome.detail, outcome.seconds + plan_seconds)
        verdict = self._judge(params, outcome, truth_before)
        self.verdicts.append(verdict)
        self._checked.clear()
        self._unplannable.clear()
        self.steps += 1
        before = self._judged_from  # the look the step is judged from (after any relook)
        typed = self._observe()
        # the robot's own verdict: what it sees (the truth only with the ground truth observer)
        done = self.goal.satisfied_by(typed.symbols.state)
        truncated = not done and self.steps >= self.max_steps
        acted_on = getattr(params, "obj", "")  # an undecodable action acts on nothing
        true_after = self.scene.poses()
        info = {
            "outcome": outcome,
            "observation": typed,
            # what the primitive truly moved besides its object: the record's, not the agent's
            "disturbed": disturbances(true_before, true_after, acted_on, phases),
            "dragged": dragged(phases, true_after, acted_on),
            # the largest move the robot saw of an object besides its own, of those it was
            # sure of before and after (its observer's)
            "seen_moved": largest_move(
                before.scene_graph, typed.scene_graph, acted_on, sure_in_both(before, typed)
            ),
            "goal_truly_holds": self.goal.satisfied_by(typed.true_symbols.state),
            "verdict": verdict,
            # how far the belief the step was planned on had its objects (the record's)
            "misbelieved": belief_errors(
                before.scene_graph,
                true_before,
                tuple(o for o in (acted_on, getattr(params, "target", "")) if o),
                self.scene.world,
            ),
        }
        return self._encode(typed), float(done), done, truncated, info

    def _judge(self, params, outcome: Outcome, before) -> Verdict:
        """The judge's verdict on the step just run, from the simulator's scene graph before
        it. Under the ground truth the outcome is the judge's own; a step no plan was run for
        (refused while planning, an undecodable action) moved nothing and is what it was."""
        if not self.believing or self.last_plan is None:
            return Verdict(outcome.status, outcome.detail)
        plan = self.last_plan
        return judge(before, self.scene.scene_graph(), params.obj, plan.expected, self._stopped)

    def check(self, action: PrimitiveParams) -> bool:
        """A dry run: whether the primitive can be planned in the scene as it is. Nothing
        moves, no step is spent, and a following `step` with the same action reuses the plan.
        Asked again in the same state, it answers from the first dry run."""
        state = self._state()
        if (action, state) in self._unplannable:
            return False
        if action in self._checked and self._checked[action][2] == state:
            return True
        start = time.perf_counter()
        plan = plan_primitive(self._planning_scene(), action)
        # Planning puts the arm back, and the held object with it, to within rounding: a plan
        # is kept with the state it leaves, which the step it is reused by compares with.
        after = self._state()
        if isinstance(plan, PlanFailure):
            self._unplannable.update(((action, state), (action, after)))
            return False
        self._checked[action] = (plan, time.perf_counter() - start, after)
        return True

    def _state(self) -> tuple:
        """What a plan is made from: the arm's joints, and every object's pose in the scene
        it is planned in (a trial of a plan ahead may have left a dry run behind it)."""
        scene = self._planning_scene()
        poses = tuple(p.position + p.orientation for p in scene.poses().values())
        return tuple(scene.robot.q()), poses, scene.held()

    def _checked_plan(self, params: PrimitiveParams) -> tuple[MotionPlan | None, float]:
        """A dry run's plan for `params` if it was made in the scene as it is now."""
        if params not in self._checked:  # most steps: no dry run, no state to compare
            return None, 0.0
        plan, seconds, state = self._checked.pop(params)
        return (plan, seconds) if state == self._state() else (None, 0.0)

    def render(self, camera: Camera | None = None) -> np.ndarray | None:
        """An RGB image from `camera` (default: the env's fixed camera)."""
        if self.scene is None:
            raise RuntimeError("call reset() before render()")
        return (camera or self.camera).capture(self.scene.bc)

    def close(self) -> None:
        if self.scene is not None:
            self.scene.close()
            self.scene = None
        if self.world is not None:
            self.world.close()
            self.world = None

    def _planning_scene(self) -> Scene:
        """Where primitives are planned, dry-run and tried: the robot's model, never the
        simulated scene."""
        return self.world.scene

    def _observe(self) -> Observation:
        if not self.believing:
            seen = self.observer.observe(self.scene)
            robot = self.scene.robot
            self.world.know(seen.scene_graph, robot.q(), robot.finger_opening())
        elif self._judged is not None:
            seen, self._judged = self._judged, None
        else:
            seen = self._seen = self._look()
        rgb = self.render() if self.render_images else None
        symbols = map_symbols(seen.scene_graph)
        if isinstance(self.observer, GroundTruth):  # what it sees is the truth: mapped once
            true_symbols = symbols
        else:
            true_symbols = map_symbols(self.scene.scene_graph())
        self._judged_from = Observation(
            seen.scene_graph,
            symbols,
            rgb,
            true_symbols,
            seen.unseen,
            seen.unknown,
            seen.uncertain,
        )
        return self._judged_from

    def _encode(self, typed: Observation) -> dict:
        return encode(self.scene.objects, typed.scene_graph, typed.symbols.state)


# made in the kitchen unless `world=` is given: the id is an entry point, resolved where the
# kitchen may be named
gymnasium.register(id=ENV_ID, entry_point="hsgplan.evaluation.gym_env:kitchen_storage_env")
