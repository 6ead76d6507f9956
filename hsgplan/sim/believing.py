"""A step seen through cameras: planned in the model of the belief, run in the scene, judged on
what the gripper feels and on the belief before and after it (`KitchenStorageEnv` with a camera
observer; the module there says what the robot knows)."""

from __future__ import annotations

import time
from functools import partial

import numpy as np

from hsgplan.domain.parameters import PickParams, PlaceParams, PrimitiveParams
from hsgplan.domain.recovery import RecoveryRules
from hsgplan.sim.actuation import holds_something
from hsgplan.sim.belief_world import BeliefWorld
from hsgplan.sim.env_types import Observation
from hsgplan.sim.motion_plans import MotionPlan, PlanFailure, overlapped, plan_transit
from hsgplan.sim.observer import CameraObserver, Look, Seen
from hsgplan.sim.outcome import SEEN_DISTURB_TOL, Outcome, Status, compare, stopped_outcome
from hsgplan.sim.primitives import Watch, run_path, run_plan
from hsgplan.sim.reach import driven, near, swept_boxes
from hsgplan.sim.robot import REST
from hsgplan.sim.scene import Scene


class BelievedSteps:
    """The env's steps and looks under a camera observer.

    What it reads of the env: `scene` (the simulated one), `world` (the robot's model of its
    belief), `observer`, `rules` (the perception rules in force), `believing`, `_checked_plan`
    (a dry run's plan) and `_observe` (the observation the agent reads); what it keeps there:
    `_seen` (the belief's last look), `_judged` (the look that judged the last step),
    `_judged_from` (the last observation), `_released` (where the last step let its object go,
    for the next look), `_stopped` (why the arm was stopped short, for the judge's record) and
    `last_plan`.
    """

    scene: Scene
    world: BeliefWorld | None
    observer: CameraObserver
    rules: RecoveryRules
    believing: bool
    _seen: Seen | None
    _judged: Seen | None
    _judged_from: Seen | Observation | None

    def _step_believed(self, params: PrimitiveParams, on_frame, on_phase) -> Outcome:
        """One primitive planned in the model of the belief, run in the scene, judged on what
        the gripper feels and on the belief before and after it."""
        start = time.perf_counter()
        watch = Watch(on_frame)
        on_frame = watch.frame
        plan, plan_seconds = self._checked_plan(params)
        relooks = 0
        if self.rules.relook and self._unsure_of(params):
            relooks = self._look_again(on_frame)
            if relooks:  # a dry run's plan was made on the older belief: planned again
                plan, plan_seconds = None, 0.0
        before = self._judged_from = self._seen
        world = self.world
        world.follow(self.scene.robot.q())
        if plan is None:
            plan = world.plan(params)
        if isinstance(plan, PlanFailure):
            seconds = time.perf_counter() - start - watch.seconds + plan_seconds
            return Outcome(plan.status, plan.detail, seconds, relooks)
        self.last_plan = plan
        stopped = self._stopped = run_plan(self.scene, plan, on_frame, on_phase)
        holds = holds_something(self.scene.robot)  # the gripper's width
        self._released = world.executed(plan, holds)
        if world.holding is not None and not holds:
            world.dropped()
        seconds = time.perf_counter() - start - watch.seconds + plan_seconds
        if isinstance(params, PickParams) and not holds:
            detail = f"the fingers closed on nothing where '{params.obj}' was believed"
            status, detail = stopped_outcome(Status.DROPPED, detail, stopped)
            return Outcome(status, detail, seconds, relooks)
        # the look that judges the step is the next observation's: made once
        self._seen = self._judged = self._look()
        status, detail = self._verdict(before, params, plan)
        # A failure seen on a look unsure of the step's objects (the arm, where the step left
        # it, hides a can it pushed into a shelf), or on any look away from the rest pose
        # (`relook_failed`), is judged again from the rest pose.
        unsure = self.rules.relook and self._unsure_of(params)
        if status != Status.SUCCESS and (unsure or self.rules.relook_failed):
            again = self._look_again(on_frame)
            if again:
                relooks += again
                self._judged = self._seen
                status, detail = self._verdict(before, params, plan)
            seconds = time.perf_counter() - start - watch.seconds + plan_seconds
        # the joints' encoders tell whether the arm got where it was driven
        status, detail = stopped_outcome(status, detail, stopped)
        return Outcome(status, detail, seconds, relooks)

    def _verdict(self, before: Seen, params: PrimitiveParams, plan: MotionPlan):
        """(status, detail) of a step from the look before it and the latest look."""
        after = self._seen
        judge = partial(
            compare,
            before.scene_graph,
            after.scene_graph,
            params.obj,
            plan.expected,
            SEEN_DISTURB_TOL,
            sure_in_both(before, after),
        )
        status, detail = judge()
        if status is Status.DISTURBED and self.rules.near_moves_only:
            status, detail = judge(self._reached(before.scene_graph, after.scene_graph, plan))
        return status, detail

    def _reached(self, before, after, plan: MotionPlan) -> frozenset[str]:
        """The objects the step could have moved, by the robot's model: believed, before or
        after it, near the boxes the arm's links swept along the plan's joints (grown down by
        the height of what a pick or place carries) or near the acted object's track."""
        obj = plan.params.obj
        carried = 0.0
        if isinstance(plan.params, PickParams | PlaceParams):
            carried = self.world.scene.world.object_type(obj).height
        boxes = swept_boxes(self.world.scene.robot, driven(plan), carried)
        track = None
        if obj in before.objects and obj in after.objects:
            track = (before.pose(obj).position, after.pose(obj).position)
        return frozenset(
            o
            for o in after.objects
            if o != obj
            and near([g.pose(o).position for g in (before, after) if o in g.objects], boxes, track)
        )

    def look_again(self, objects: tuple[str, ...]) -> Observation | None:
        """With a camera observer and the `relook` rule: if the belief is unsure of any of
        `objects`, the arm moves out of the cameras' way and the robot looks again; the new
        observation, or None where nothing was done (sure of them, or already at rest). The
        agent asks before it believes its goal reached."""
        if not (self.believing and self.rules.relook) or self._seen is None:
            return None
        if not set(objects) & set(self._seen.uncertain) or not self._look_again(None):
            return None
        self._judged = self._seen
        return self._observe()

    def _unsure_of(self, params: PrimitiveParams) -> bool:
        """Whether the belief is unsure of an object the primitive acts on or places onto."""
        uncertain = self._seen.uncertain
        target = getattr(params, "target", None)
        return params.obj in uncertain or target in uncertain

    def _look_again(self, on_frame) -> int:
        """The arm moves to its rest pose, out of the cameras' way, along a path planned in
        the model, and the robot looks again: 1 if it did, 0 if it was there already or no
        path was found."""
        q = self.scene.robot.q()
        if np.allclose(q, REST, atol=1e-3):
            return 0
        self.world.follow(q)
        # a belief the arm stands in is wrong, and would keep the arm where it hides things
        path = plan_transit(self.world.scene, REST, overlapped(self.world.scene))
        if path is None:
            return 0
        run_path(self.scene, path, on_frame)
        self.scene.feel_hold()  # what friction alone held may have slipped out on the way
        self._seen = self._look()
        return 1

    def _look(self) -> Seen:
        """A look at the scene as it stands; the model's arm is brought to the real joints
        first, since the look carries its links."""
        scene, world = self.scene, self.world
        q = scene.robot.q()
        world.follow(q)
        look = Look(
            np.stack([c.capture(scene.bc) for c in self.observer.cameras]),
            self.observer.cameras,
            q,
            world.holding,
            world.held_pose(),
            self._released,
            world.arm(),
        )
        self._released = None
        seen = self.observer.look(look)
        world.believe(seen.scene_graph)
        return seen


def sure_in_both(before: Seen | Observation, after: Seen | Observation) -> frozenset[str]:
    """The objects a look before and a look after a step were both sure of (seen by several
    views): only their poses are compared by distance; a single view's depth is compared by
    the symbolic location it gives."""
    unsure = set(before.uncertain) | set(after.uncertain)
    return frozenset(after.scene_graph.objects) - unsure
