"""`hsgplan collect visited`: f_reach's labels from the states the agent itself visits.

`collect reach` stages its states with every object where the scene sampler puts it. In the
loop, most objects on a shelf top were put there by the place network, which learned to leave
its neighbours free to be taken up again (`data/motion_trials.py`): a box among three others
there is taken up far more often than a staged one. f_reach, which reads only the symbolic
state, learns the staged odds, and the planner then finds nothing reachable where one pick
would do (`no_subgoal`).

Here the learned agent (`learned`: the regression planner of the checkpoint named, by default
the shipped one, and the shipped GNN motion networks, every recovery rule on, going on after a
failed primitive; `data/reach/visited` was collected by `checkpoints/task-staged`) runs episodes
towards random goals, and in every state it meets, before it decides, up to `ACTIONS_PER_STATE`
actions are executed from that state as `collect reach` executes them from a staged one
(`choose_actions`, `execute_action`), the scene put back after each; then the agent's own step
goes on. Nothing here asks the hand-written rules: what the world shows is the label. The
episodes run in the kitchen, or in the world of a scene file, or round a folder of them.

The goals are the train split's (`evaluation.splits`), drawn from `GOAL_SEEDS.start + seed`,
apart from every seed an evaluation reports on or tunes on; each row records its goal and its
start scene's seed, which `hsgplan splits check` holds apart from the test split. A work item
is one episode; its row holds every state it visited (`data/world_trials.py`), so an
interruption loses at most the episodes in flight and repeats nothing logged.
"""

from __future__ import annotations

import functools
import random
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hsgplan.collect.reach import (
    ACTIONS_PER_STATE,
    MAX_PARAMS,
    choose_actions,
    run_collection,
    trials_from_here,
)
from hsgplan.data.world_trials import WorldTrial, state_row, trials_of
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.scene import World
from hsgplan.domain.scene_file import default_world, read_world, read_worlds
from hsgplan.evaluation.seeds import GOAL_SEEDS, episode_seed
from hsgplan.evaluation.splits import TRAIN, split_goals

AGENT = "learned"


@dataclass(frozen=True)
class VisitedItem:
    """One episode: the unit of work and of what an interruption loses."""

    seed: int
    size: int
    index: int
    actions_per_state: int = ACTIONS_PER_STATE
    max_params: int = MAX_PARAMS
    checkpoint: str | None = None  # the agent's task planner (None: the shipped one)
    scene: str | None = None  # a scene file's path (None: the kitchen)
    motion_checkpoints: str | None = None  # the agent's motion networks (None: the shipped ones)

    @property
    def key(self) -> str:
        return f"{self.seed}/{self.size}/{self.index}"

    @property
    def episode_seed(self) -> int:
        return GOAL_SEEDS.start + episode_seed(self.seed, self.size, self.index)


@functools.cache
def _agent(checkpoint: str | None = None, motion_checkpoints: str | None = None):
    from hsgplan.agents.registry import make_agent
    from hsgplan.paths import MOTION_CHECKPOINTS, TASK_CHECKPOINT

    return make_agent(
        AGENT, Path(checkpoint or TASK_CHECKPOINT), Path(motion_checkpoints or MOTION_CHECKPOINTS)
    )


@functools.cache
def _world(scene: str | None) -> World:
    return default_world() if scene is None else read_world(Path(scene))


def _goal(item: VisitedItem):
    # the first k goals of a seed are the same however many are drawn: a rerun may ask for more
    goals = split_goals(
        TRAIN,
        item.size,
        item.index + 1,
        GOAL_SEEDS.start + item.seed,
        stacking=item.size > 2,
        world=_world(item.scene),
    )
    return goals[item.index]


def run_visited_item(item: VisitedItem) -> dict:
    """The worker entry point: one episode, and the trials run from every state it visited,
    as one row."""
    return explore_episode(item, _goal(item))


def explore_episode(item: VisitedItem, goal) -> dict:
    """The agent's episode towards `goal`, with the trials from every state it met, as one
    row. Only drawing the goal asks the symbolic package (its generator); nothing here does."""
    from hsgplan.evaluation.episode import run_episode
    from hsgplan.sim.env import KitchenStorageEnv

    env = KitchenStorageEnv(visuals=False, world=_world(item.scene))
    rng = random.Random(f"visited-actions-{item.key}")
    states: list[dict] = []

    def explore(_record, obs) -> None:
        state = obs.symbols.state
        if obs.symbols.anomalies or goal.satisfied_by(state):
            return  # the episode ends here: nothing is decided from this state
        actions = choose_actions(state, rng, item.actions_per_state)
        scene = env.scene
        rng_before = scene.rng
        scene.rng = np.random.default_rng(rng.getrandbits(64))
        states.append(state_row(state, trials_from_here(scene, state, actions, item.max_params)))
        scene.rng = rng_before  # the agent's episode goes on as it would have

    agent = _agent(item.checkpoint, item.motion_checkpoints)
    record = run_episode(env, agent, goal, item.episode_seed, on_step=explore)
    # the goal and the start scene's seed it drew: what `hsgplan splits check` reads
    return {
        "states": states,
        "goal": str(goal),
        "seed": item.episode_seed,
        "success": record.success,
    }


@dataclass(frozen=True)
class VisitedSummary:
    episodes: int  # asked for, logged before or run now
    states: int
    trials: int
    by_status: dict[str, int]
    ran: int
    seconds: float


def collect_visited(
    out: Path,
    episodes: int,
    sizes: tuple[int, ...],
    seed: int = 0,
    workers: int = 2,
    ray: str | None = None,
    on_item: Callable[[dict], None] | None = None,
    checkpoint: Path | None = None,
    *,
    scene: Path | None = None,
    motion_checkpoints: Path | None = None,
) -> VisitedSummary:
    """`episodes` episodes of each size, logged to the run folder `out` (a collection of
    executed primitives, as `collect reach` makes: `train task` reads it as `loop_trials`), the
    agent's task planner from `checkpoint` and its motion networks from `motion_checkpoints`
    (None: the shipped ones). `scene`: the episodes run in this scene file's world, or round a
    folder of them, episode i of a size in the i-th file (default: the kitchen); the path is
    kept in the folder's configuration, where `train task` finds it. A rerun keeps what is
    logged and runs only the missing episodes; a folder made with other settings, checkpoints
    or scene is refused."""
    if episodes < 1:
        raise InvalidInputError(f"--episodes {episodes}: need at least one")
    if not sizes or min(sizes) < 2:
        raise InvalidInputError("--sizes: episodes need at least two objects")
    if GOAL_SEEDS.start + seed not in TRAIN.seeds:
        raise InvalidInputError(
            f"--seed {seed}: a collection draws from the train split's seeds "
            f"({TRAIN.seeds.start}..{TRAIN.seeds.stop - 1}), so at most "
            f"{TRAIN.seeds.stop - 1 - GOAL_SEEDS.start}"
        )
    start = time.perf_counter()
    from hsgplan.agents.registry import agent_checkpoints, check_reads
    from hsgplan.checkpoint import fingerprint
    from hsgplan.paths import MOTION_CHECKPOINTS, TASK_CHECKPOINT

    folder = None if checkpoint is None else str(checkpoint)
    motion = None if motion_checkpoints is None else str(motion_checkpoints)
    read = [Path(folder or TASK_CHECKPOINT), Path(motion or MOTION_CHECKPOINTS)]
    worlds: dict[str | None, World] = {None: default_world()}
    if scene is not None:  # a kitchen collection records no scene, as before scenes were given
        worlds = {str(p): w for p, w in read_worlds(scene).items()}
    # a missing or unreadable checkpoint, or one that cannot read a scene's names, is refused
    # before anything is written
    _agent(folder, motion)
    for world in worlds.values():
        check_reads(agent_checkpoints(AGENT, *read), world, scene)
    config = {
        "kind": "reach",
        "unit": "visited episode",
        "seed": seed,
        "agent": AGENT,
        "actions_per_state": ACTIONS_PER_STATE,
        "max_params": MAX_PARAMS,
        "fingerprint": fingerprint(read),
        "goals": TRAIN.name,  # its goals' split (`evaluation.splits`)
    }
    if scene is not None:
        config["scene"] = str(scene)
    refusal = (
        f"'{out}' holds a collection made with other settings, checkpoints, scene or goals; "
        "use another --out"
    )
    files = list(worlds)
    items = [
        VisitedItem(
            seed, n, i, checkpoint=folder, scene=files[i % len(files)], motion_checkpoints=motion
        )
        for n in sorted(set(sizes))
        for i in range(episodes)
    ]
    rows, ran = run_collection(out, run_visited_item, items, config, refusal, workers, ray, on_item)
    trials: list[WorldTrial] = [
        t for item, row in zip(items, rows, strict=True) for t in trials_of(row, worlds[item.scene])
    ]
    return VisitedSummary(
        len(items),
        sum(len(row["states"]) for row in rows),
        len(trials),
        dict(sorted(Counter(t.status for t in trials).items())),
        ran,
        time.perf_counter() - start,
    )
