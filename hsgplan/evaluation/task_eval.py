"""Symbolic evaluation of task planners: the closed loop in the transition model, no physics.

Each goal starts from a seeded random state (`random_state`); the planner picks an action, the
transition model applies it, until the goal holds or 50 steps pass. Plan length is compared
with Fast Downward's plan from the same start (shortest plans up to 6 objects, weighted A*
beyond), and every decision is timed.
"""

from __future__ import annotations

import contextlib
import json
import multiprocessing
import random
import statistics
from collections import Counter
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass
from pathlib import Path

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.goals import Goal, parse_goal, read_goal_file
from hsgplan.evaluation.protocol import episode_seed
from hsgplan.evaluation.run_folder import RESULTS, claim, logged_rows
from hsgplan.symbolic.generator import random_goals, random_state
from hsgplan.symbolic.transition import apply, why_not

MAX_STEPS = 50
PLANNERS = ("regression", "forward", "fd")


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


def make_planner(name: str, checkpoint: Path, seed: int):
    from hsgplan.planning.regression.planner import (
        FastDownwardTaskPlanner,
        ForwardPlanner,
        RegressionPlanner,
    )

    if name == "regression":
        return RegressionPlanner(checkpoint, seed=seed)
    if name == "forward":
        return ForwardPlanner(checkpoint)
    if name == "fd":
        return FastDownwardTaskPlanner()
    raise InvalidInputError(f"unknown planner '{name}' (known: {', '.join(PLANNERS)})")


def run_task_episode(planner, goal: Goal, seed: int, fd_length: int) -> TaskEpisode:
    state = random_state(goal.objects, random.Random(f"task-{seed}"))
    times, failure, steps = [], None, 0
    while not goal.satisfied_by(state):
        if steps >= MAX_STEPS:
            failure = "overstep"
            break
        decision = planner.next_action(state, goal)
        times.append(1000 * decision.seconds)
        if decision.action is None:
            failure = "no_subgoal"
            break
        if why_not(state, decision.action) is not None:
            failure = "inapplicable"
            break
        state = apply(state, decision.action)
        steps += 1
    done = sum(state.holds(lit) for lit in goal.literals) / len(goal.literals)
    return TaskEpisode(
        goal.size, seed, str(goal), failure is None, failure, steps, fd_length, done, tuple(times)
    )


def fd_length(goal: Goal, seed: int) -> int:
    from hsgplan.planning.fast_downward import FastDownwardPlanner

    state = random_state(goal.objects, random.Random(f"task-{seed}"))
    return len(FastDownwardPlanner().plan(state, goal))


def _work(args) -> dict:
    import torch

    torch.set_num_threads(1)  # one core per worker: the pool already fills the machine
    name, checkpoint, goal_text, seed = args
    goal = parse_goal(goal_text)
    planner = make_planner(name, Path(checkpoint), seed)
    return asdict(run_task_episode(planner, goal, seed, fd_length(goal, seed)))


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
) -> list[TaskEpisode]:
    """Every episode, `workers` at a time. With `run_dir`, finished episodes are appended to
    its `episodes.jsonl` as they finish, and a run started again skips them."""
    make_planner(planner, checkpoint, seed)  # a bad name or checkpoint fails here, once
    if goals < 0:
        raise InvalidInputError(f"--goals {goals}: the number of goals cannot be negative")
    if goals_file:
        chosen = [g for g in read_goal_file(goals_file) if g.size in sizes]
        jobs = [(g, episode_seed(seed, g.size, i)) for i, g in enumerate(chosen)]
    else:
        jobs = [
            (g, episode_seed(seed, n, i))
            for n in sizes
            for i, g in enumerate(random_goals(n, goals, seed, stacking=n > 2))
        ]
    keys = [(str(g), s) for g, s in jobs]
    done = _load_done(run_dir, planner, checkpoint) if run_dir else {}
    for key in keys:
        if key in done and on_episode:
            on_episode(done[key])
    todo = [(planner, str(checkpoint), g, s) for g, s in keys if (g, s) not in done]
    # spawn, not fork: this process has loaded torch, and a forked child of a process with live
    # OpenMP threads hangs (measured: the workers sat idle)
    with (
        open(run_dir / RESULTS, "a") if run_dir else contextlib.nullcontext() as log,
        ProcessPoolExecutor(
            max(1, workers), mp_context=multiprocessing.get_context("spawn")
        ) as pool,
    ):
        for row in pool.map(_work, todo, chunksize=4):
            episode = TaskEpisode(**{**row, "decision_ms": tuple(row["decision_ms"])})
            done[(episode.goal, episode.seed)] = episode
            if log:
                log.write(json.dumps(row) + "\n")
                log.flush()
            if on_episode:
                on_episode(episode)
    return [done[k] for k in keys]


def _load_done(run_dir: Path, planner: str, checkpoint: Path) -> dict[tuple, TaskEpisode]:
    """Episodes a run folder already holds; refuses one made by another planner."""
    config = {"planner": planner, "checkpoint": str(checkpoint)}
    claim(run_dir, config, f"'{run_dir}' holds a run of another planner")
    done = {}
    for row in logged_rows(run_dir):
        try:
            e = TaskEpisode(**{**row, "decision_ms": tuple(row["decision_ms"])})
        except (KeyError, TypeError):
            continue
        done[(e.goal, e.seed)] = e
    return done


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
            "plan_length_ratio": (
                statistics.mean(e.steps / e.fd_length for e in wins) if wins else None
            ),
            "ms_per_decision": statistics.median(t for e in es for t in e.decision_ms)
            if any(e.decision_ms for e in es)
            else None,
        }
    return {"by_size": by_size}
