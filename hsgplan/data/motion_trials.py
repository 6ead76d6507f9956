"""Trying uniformly sampled motion parameters in staged scenes: the unit of work of the
self-supervised collection.

Work comes in chunks of `TASKS_PER_CHUNK` consecutive tasks. A chunk runs in a fresh scene
(its own physics client), so its trials depend on `(primitive, seed, chunk)` alone, never on
which process or machine ran it or what that process ran before. In each staged task the
collector saves the physics state and tries `ATTEMPTS_PER_TASK[primitive]` parameter choices,
drawn uniformly over the bins, each from that same state. A trial is a training sample when the
primitive's intended literal holds afterwards and nothing else was knocked out of place
(`hsgplan.sim.outcome.verify`), and, for a place, when it leaves every object on the target
surface that could be taken up before (a pick dry run with the hand empty) still able to be
taken up, the placed one included (`Status.BLOCKS_PICK` otherwise): a place that walls in a
neighbour, or itself, succeeds now and makes a later pick fail, which is the commonest way a
long episode fails (README, Table 1).
"""

from __future__ import annotations

import random
from dataclasses import dataclass

import numpy as np

from hsgplan.data.motion_tasks import P_FELL_SHORT, MotionTask, draw_task
from hsgplan.domain.parameters import BINS, MotionPrimitive, params_for
from hsgplan.domain.predicates import Predicate
from hsgplan.domain.scene_file import read_world
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.names import names_world
from hsgplan.sim.motion_plans import can_pick
from hsgplan.sim.outcome import Outcome, Status
from hsgplan.sim.primitives import execute
from hsgplan.sim.scene import Scene
from hsgplan.sim.staging import move_short_of, stage

TASKS_PER_CHUNK = 32
# Staging a scene costs about one push trial (a cProfile of 3 chunks: 19 ms against 23 ms).
# One uniformly drawn push in seven succeeds, one place in three fails: eight pushes a scene
# still give about one sample per scene (place's four give nearly three), and a push sample
# costs a fifth less time than with four (`hsgplan bench push-settings`, docs/decisions.md).
ATTEMPTS_PER_TASK: dict[MotionPrimitive, int] = {MotionPrimitive.PLACE: 4, MotionPrimitive.PUSH: 8}


@dataclass(frozen=True)
class Trial:
    """One parameter choice tried in one staged task, and what came of it.

    Attributes:
        task, attempt: which task of the stream, which try within it.
        crowding: the task's crowding (objects already on the target surface or in the shelf).
        obj, target: the object placed or pushed, the surface or shelf it goes to.
        before: the geometric scene graph the primitive started from.
        bins: (x_bin, y_bin) for place, (angle_bin, dist_bin) for push.
        status: the primitive's outcome; `Status.SUCCESS` makes the trial a training sample.
    """

    task: int
    attempt: int
    crowding: int
    obj: str
    target: str
    before: GeometricSceneGraph
    bins: tuple[int, int]
    status: Status

    @property
    def ok(self) -> bool:
        return self.status is Status.SUCCESS


@dataclass(frozen=True)
class ChunkResult:
    primitive: MotionPrimitive
    seed: int
    chunk: int
    trials: tuple[Trial, ...]
    unstaged: int  # tasks whose scene could not be staged (no trials)


def run_chunk(
    primitive: str,
    seed: int,
    chunk: int,
    tasks_per_chunk: int = TASKS_PER_CHUNK,
    scene_file: str | None = None,
    fell_short: float = P_FELL_SHORT,
) -> ChunkResult:
    """Stage every task of a chunk and try it; the worker entry point (pool or Ray). The
    tasks are drawn and staged in the world of `scene_file`, else in the kitchen, whose names
    the shipped data's columns index (`data.motion_store`)."""
    kind = MotionPrimitive(primitive)
    world = names_world() if scene_file is None else read_world(scene_file)
    trials: list[Trial] = []
    unstaged = 0
    with Scene((), seed=seed, visuals=False, world=world) as scene:
        for index in range(chunk * tasks_per_chunk, (chunk + 1) * tasks_per_chunk):
            got = run_task(scene, draw_task(kind, seed, index, world, fell_short))
            unstaged += got is None
            trials += got or []
    return ChunkResult(kind, seed, chunk, tuple(trials), unstaged)


@dataclass(frozen=True)
class StagedTask:
    """A task staged in a scene, ready to be tried from the same state again and again."""

    task: MotionTask
    snapshot: int  # the physics state, saved
    grip: tuple[int | None, bool]  # the hand's hold (`Panda.grip`: not part of a saved state)
    before: GeometricSceneGraph
    rng: random.Random


def stage_task(scene: Scene, task: MotionTask) -> StagedTask | None:
    """Stage a task in the scene (replacing whatever objects it held); None when the
    arrangement could not be staged. `release` the result when done with it."""
    for o in scene.objects:
        scene.remove_object(o)
    for o in task.state.objects:
        scene.add_object(o)
    rng = random.Random(f"trials-{task.primitive.value}-{task.seed}-{task.index}")
    scene.rng = np.random.default_rng(rng.getrandbits(64))
    if not stage(scene, task.state, rng):
        return None
    if task.front_gap is not None and not move_short_of(
        scene, task.state, task.obj, task.target, task.front_gap
    ):
        return None
    return StagedTask(task, scene.snapshot(), scene.robot.grip(), scene.scene_graph(), rng)


def try_params(scene: Scene, staged: StagedTask, params) -> Outcome:
    """Run one primitive from the staged state."""
    scene.back_to(staged.snapshot, staged.grip)
    return execute(scene, params)


def release(scene: Scene, staged: StagedTask) -> None:
    scene.bc.removeState(staged.snapshot)


def pickable(scene: Scene, objects: list[str]) -> set[str]:
    """The objects a pick could take up from the scene as it is (dry runs; the hand empty)."""
    return {o for o in objects if can_pick(scene, o)}


def _neighbours(task: MotionTask) -> list[str]:
    """The objects resting directly on a place task's target surface."""
    state = task.state
    return [
        o
        for o in state.objects
        if o != task.obj
        and state.location(o).predicate is Predicate.ON
        and state.location(o).args[1] == task.target
    ]


def _pickable_before(scene: Scene, staged: StagedTask) -> set[str]:
    """The neighbours that could be taken up before the place, the held object set aside."""
    scene.restore(staged.snapshot)
    scene.robot.detach()
    scene.park(staged.task.obj)
    return pickable(scene, _neighbours(staged.task))


def run_task(scene: Scene, task: MotionTask) -> list[Trial] | None:
    """Stage a task and try `ATTEMPTS_PER_TASK` uniformly drawn bin pairs in it; None when
    the arrangement could not be staged."""
    staged = stage_task(scene, task)
    if staged is None:
        return None
    trials = []
    nx, ny = BINS[task.primitive]
    place = task.primitive is MotionPrimitive.PLACE
    wanted = _pickable_before(scene, staged) | {task.obj} if place else set()
    for attempt in range(ATTEMPTS_PER_TASK[task.primitive]):
        bins = (staged.rng.randrange(nx), staged.rng.randrange(ny))
        outcome = try_params(scene, staged, params_for(task.primitive, task.obj, task.target, bins))
        if place and outcome.ok and pickable(scene, sorted(wanted)) != wanted:
            outcome = Outcome(Status.BLOCKS_PICK, "cannot be taken up any more", outcome.seconds)
        trials.append(
            Trial(
                task.index,
                attempt,
                task.crowding,
                task.obj,
                task.target,
                staged.before,
                bins,
                outcome.status,
            )
        )
    release(scene, staged)
    return trials
