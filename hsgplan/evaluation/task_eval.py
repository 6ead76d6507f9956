"""Symbolic evaluation of task planners: the closed loop in the transition model, no physics.

Each goal starts from a seeded random state (`random_state`); the planner picks an action, the
transition model applies it, until the goal holds or 50 steps pass. The transition model is the
world here, never the planner's: an action whose preconditions fail leaves the state as it was
and costs its step (a wasted action, counted per episode), as a failed primitive does in the
simulated world under the recovering protocol; under the paper's (`protocol="paper"`) it ends
the episode (`failed_primitive`), and the planner runs without recovery rules. Plan length is
compared
with Fast Downward's plan from the same start (shortest plans up to 6 objects, weighted A*
beyond), and every decision is timed.
"""

from __future__ import annotations

import random
import statistics
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, replace
from pathlib import Path

from hsgplan.agents.goal_scope import check_planner_goal
from hsgplan.agents.registry import LEARNED_PLANNERS, check_reads, make_planner
from hsgplan.checkpoint import fingerprint
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.goals import Goal, parse_goal, read_goal_file
from hsgplan.domain.recovery import PAPER, PROTOCOLS, RECOVERING, RecoveryRules
from hsgplan.domain.scene import World
from hsgplan.domain.scene_file import default_world, read_world, read_worlds
from hsgplan.domain.world import MAX_STEPS
from hsgplan.evaluation.failures import Failure
from hsgplan.evaluation.seeds import episode_seed
from hsgplan.runner.items import run_items
from hsgplan.symbolic.generator import random_goals, random_state
from hsgplan.symbolic.transition import apply, why_not


@dataclass(frozen=True)
class TaskEpisode:
    size: int
    seed: int
    goal: str
    success: bool
    failure: str | None
    steps: int
    fd_length: int
    subgoal_completion: float
    decision_ms: tuple[float, ...]
    # actions whose preconditions did not hold: the state stayed, the step was spent
    wasted: int = 0
    scene: str | None = None  # the scene file it ran in; None: the kitchen


def run_task_episode(
    planner, goal: Goal, seed: int, fd_length: int, end_at_failure: bool = False
) -> TaskEpisode:
    """One episode; with `end_at_failure` (the paper's protocol) the first inapplicable action
    ends it."""
    state = random_state(goal.objects, random.Random(f"task-{seed}"), world=goal.world)
    times, failure, steps, wasted = [], None, 0, 0
    while not goal.satisfied_by(state):
        if steps >= MAX_STEPS:
            failure = Failure.OVERSTEP
            break
        decision = planner.next_action(state, goal)
        times.append(1000 * decision.seconds)
        if decision.action is None:
            failure = Failure.NO_SUBGOAL
            break
        steps += 1
        # As a primitive fails in the world, an inapplicable action changes nothing here and
        # costs its step; the planner is told nothing but the state it observes again.
        if why_not(state, decision.action) is not None:
            wasted += 1
            if end_at_failure:
                failure = Failure.FAILED_PRIMITIVE
                break
            continue
        state = apply(state, decision.action)
    done = sum(state.holds(lit) for lit in goal.literals) / len(goal.literals)
    failure = None if failure is None else str(failure)
    return TaskEpisode(
        goal.size,
        seed,
        str(goal),
        failure is None,
        failure,
        steps,
        fd_length,
        done,
        tuple(times),
        wasted,
    )


def fd_length(goal: Goal, seed: int) -> int:
    """The reference plan's length, 0 where Fast Downward finds none in its time: the length
    only scales the plan-length ratio of won episodes (which skips 0), so a reference search
    that runs out of time on a busy machine must not end the evaluation."""
    from hsgplan.planning.fast_downward import FastDownwardPlanner, NoPlanError

    state = random_state(goal.objects, random.Random(f"task-{seed}"), world=goal.world)
    try:
        return len(FastDownwardPlanner().plan(state, goal))
    except NoPlanError:
        return 0


@dataclass(frozen=True)
class TaskJob:
    """One episode of an `eval task` run: which planner, from which checkpoint, on which goal."""

    planner: str
    checkpoint: str
    goal: str
    seed: int
    protocol: str = RECOVERING
    scene: str | None = None  # a scene file; None: the kitchen

    @property
    def key(self) -> str:
        where = f"{Path(self.scene).stem}/" if self.scene else ""
        return f"{where}{self.seed}/{self.goal}"


def run_task_job(job: TaskJob) -> dict:
    """One episode in this process (a worker): the episode as JSON."""
    import torch

    torch.set_num_threads(1)  # one core per worker: the pool already fills the machine
    goal = parse_goal(job.goal, world=read_world(job.scene) if job.scene else default_world())
    paper = job.protocol == PAPER
    rules = RecoveryRules.none() if paper else RecoveryRules()
    planner = make_planner(job.planner, Path(job.checkpoint), rules)
    planner.reset(goal, job.seed)
    length = fd_length(goal, job.seed)
    episode = run_task_episode(planner, goal, job.seed, length, end_at_failure=paper)
    return asdict(replace(episode, scene=job.scene))


def evaluate_task(
    planner: str,
    checkpoint: Path,
    sizes: Sequence[int],
    goals: int,
    seed: int,
    goals_file: Path | None = None,
    workers: int = 2,
    on_episode: Callable[[TaskEpisode], None] | None = None,
    run_dir: Path | None = None,
    ray: str | None = None,
    protocol: str = RECOVERING,
    scene: Path | None = None,
    split: str | None = None,
) -> list[TaskEpisode]:
    """Every episode, `workers` at a time, under `protocol` (one of PROTOCOLS), in the world of
    the scene file `scene`, or of each scene file in the folder `scene`, with the same goal
    seeds in each (default: the kitchen), its goals drawn from the `split`'s share of the goal
    space (`evaluation.splits`; None: the whole space, exploration). With `run_dir`, finished
    episodes are appended to its `episodes.jsonl` as they finish, and a run started again
    skips them."""
    if protocol not in PROTOCOLS:
        raise InvalidInputError(f"protocol '{protocol}': one of {', '.join(PROTOCOLS)}")
    worlds = scene_files(scene)
    for path, world in worlds.items():
        if planner in LEARNED_PLANNERS:
            check_reads([checkpoint], world, path)
    make_planner(planner, checkpoint)  # a bad name or checkpoint fails here, once
    if goals < 0:
        raise InvalidInputError(f"--goals {goals}: the number of goals cannot be negative")
    from hsgplan.evaluation.splits import check_seed, split_goals, split_named

    share = split_named(split) if split else None
    if share is not None:
        if goals_file:
            raise InvalidInputError("--split draws its goals: give no --goals-file with it")
        check_seed(share, seed)
    jobs = []
    for path, world in worlds.items():
        if goals_file:
            chosen = [g for g in read_goal_file(goals_file, world) if g.size in sizes]
            for g in chosen:  # a goal the planner is not for: refused before any episode
                check_planner_goal(planner, g)
            drawn = [(g, episode_seed(seed, g.size, i)) for i, g in enumerate(chosen)]
        else:
            drawn = [
                (g, episode_seed(seed, n, i))
                for n in sizes
                for i, g in enumerate(
                    split_goals(share, n, goals, seed, stacking=n > 2, world=world)
                    if share
                    else random_goals(n, goals, seed, stacking=n > 2, world=world)
                )
            ]
        where = str(path) if path else None
        jobs += [TaskJob(planner, str(checkpoint), str(g), s, protocol, where) for g, s in drawn]
    if not jobs:
        raise InvalidInputError(
            f"'{goals_file}' holds no goal of the sizes asked for"
            if goals_file
            else "--goals 0: nothing to evaluate"
        )
    learned = [checkpoint] if planner in LEARNED_PLANNERS else []
    files = [*learned, *([goals_file] if goals_file else []), *(p for p in worlds if p)]
    rows = run_items(
        run_task_job,
        jobs,
        key=lambda job: job.key,
        run_dir=run_dir,
        kind="eval-task",
        config={
            "planner": planner,
            "checkpoint": str(checkpoint),
            **({"protocol": protocol} if protocol != RECOVERING else {}),
            **({"scene": str(scene)} if scene else {}),
            **({"split": split} if split else {}),
            "fingerprint": fingerprint(files),
        },
        workers=workers,
        ray=ray,
        on_result=on_episode and (lambda row: on_episode(_episode(row))),
    )
    return [_episode(row) for row in rows]


def scene_files(scene: Path | None) -> dict[Path | None, World]:
    """The worlds of a scene file, or of every `.toml` in a folder; {None: the kitchen}
    without one."""
    return {None: default_world()} if scene is None else read_worlds(scene)


def _episode(row: dict) -> TaskEpisode:
    return TaskEpisode(**{**row, "decision_ms": tuple(row["decision_ms"])})


def summarize_task(episodes: Sequence[TaskEpisode]) -> dict:
    by_size = {}
    for n in sorted({e.size for e in episodes}):
        es = [e for e in episodes if e.size == n]
        wins = [e for e in es if e.success and e.fd_length > 0]
        by_size[str(n)] = {
            "success_rate": sum(e.success for e in es) / len(es),
            "subgoal_completion": sum(e.subgoal_completion for e in es) / len(es),
            "episodes": len(es),
            "failures": dict(Counter(e.failure for e in es if e.failure)),
            "wasted_per_episode": sum(e.wasted for e in es) / len(es),
            "plan_length_ratio": (
                statistics.mean(e.steps / e.fd_length for e in wins) if wins else None
            ),
            "ms_per_decision": statistics.median(t for e in es for t in e.decision_ms)
            if any(e.decision_ms for e in es)
            else None,
        }
    return {"by_size": by_size}
