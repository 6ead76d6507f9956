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
goes on. Nothing here asks the hand-written rules: what the world shows is the label.

The goals are drawn from `GOAL_SEEDS.start + seed`, apart from every seed an evaluation
reports on or tunes on (`evaluation.seeds`). A work item is one episode; its row holds every
state it visited (`data/world_trials.py`), so an interruption loses at most the episodes in
flight and repeats nothing logged.
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
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.evaluation.seeds import GOAL_SEEDS, episode_seed

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

    @property
    def key(self) -> str:
        return f"{self.seed}/{self.size}/{self.index}"

    @property
    def episode_seed(self) -> int:
        return GOAL_SEEDS.start + episode_seed(self.seed, self.size, self.index)


@functools.cache
def _agent(checkpoint: str | None = None):
    from hsgplan.agents.registry import make_agent
    from hsgplan.paths import TASK_CHECKPOINT

    return make_agent(AGENT, Path(checkpoint or TASK_CHECKPOINT))


def _goal(item: VisitedItem):
    from hsgplan.symbolic.generator import random_goals

    # the first k goals of a seed are the same however many are drawn: a rerun may ask for more
    goals = random_goals(
        item.size,
        item.index + 1,
        GOAL_SEEDS.start + item.seed,
        stacking=item.size > 2,
        world=KITCHEN,
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

    env = KitchenStorageEnv(visuals=False, world=KITCHEN)
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

    record = run_episode(env, _agent(item.checkpoint), goal, item.episode_seed, on_step=explore)
    return {"states": states, "goal": str(goal), "success": record.success}


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
) -> VisitedSummary:
    """`episodes` episodes of each size, logged to the run folder `out` (a collection of
    executed primitives, as `collect reach` makes: `train task` reads it as `loop_trials`), the
    agent's task planner from `checkpoint` (None: the shipped one). A rerun keeps what is logged
    and runs only the missing episodes; a folder made with other settings or checkpoints is
    refused."""
    if episodes < 1:
        raise InvalidInputError(f"--episodes {episodes}: need at least one")
    if not sizes or min(sizes) < 2:
        raise InvalidInputError("--sizes: episodes need at least two objects")
    start = time.perf_counter()
    from hsgplan.checkpoint import fingerprint
    from hsgplan.paths import MOTION_CHECKPOINTS, TASK_CHECKPOINT

    folder = None if checkpoint is None else str(checkpoint)
    _agent(folder)  # a missing or unreadable checkpoint is refused before anything is written
    config = {
        "kind": "reach",
        "unit": "visited episode",
        "seed": seed,
        "agent": AGENT,
        "actions_per_state": ACTIONS_PER_STATE,
        "max_params": MAX_PARAMS,
        "fingerprint": fingerprint([Path(folder or TASK_CHECKPOINT), Path(MOTION_CHECKPOINTS)]),
    }
    refusal = (
        f"'{out}' holds a collection made with other settings or checkpoints; use another --out"
    )
    items = [
        VisitedItem(seed, n, i, checkpoint=folder)
        for n in sorted(set(sizes))
        for i in range(episodes)
    ]
    rows, ran = run_collection(out, run_visited_item, items, config, refusal, workers, ray, on_item)
    trials: list[WorldTrial] = [t for row in rows for t in trials_of(row, KITCHEN)]
    return VisitedSummary(
        len(items),
        sum(len(row["states"]) for row in rows),
        len(trials),
        dict(sorted(Counter(t.status for t in trials).items())),
        ran,
        time.perf_counter() - start,
    )
