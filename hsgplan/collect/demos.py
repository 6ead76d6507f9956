"""Recording the demonstrations: oracle episodes in the simulated world, one per task of
`hsgplan.data.demos.TASKS`, appended to the dataset folder as each finishes (an interrupted
recording, started again, records only the tasks that are missing). With `rounds` > 1 the 18
tasks are recorded again in scenes of their own, round after round: the larger sets a learning
curve trains on (round 1 is the paper's set).

A demonstration's scene holds the objects its goal names, or, with `full_scene`, one object of
every type (the paper does not say its demonstrations' scenes hold only the named objects):
the others rest wherever the sampler puts them, and the oracle moves them when they are in the
way.

With a scene file (`scene`), the demonstrations are recorded in its world; the tasks name the
kitchen's groceries and shelves, so the scene must hold them (a layout of the kitchen)."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

from hsgplan.agents.registry import make_agent
from hsgplan.data.demos import DEMOS, FORMAT, META, TASKS, VERSION, Demo, read_demos
from hsgplan.domain.checks import read_json
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.goals import parse_goal
from hsgplan.domain.scene import World
from hsgplan.domain.scene_file import default_world, read_world
from hsgplan.evaluation.episode import run_episode
from hsgplan.files import write_atomically
from hsgplan.runner.lock import hold_folder
from hsgplan.runner.run_folder import check_own
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.sim.env import KitchenStorageEnv, ResetOptions

RETRIES = 5
# a later round's scene seeds lie this far apart, clear of the first round's
ROUND_STRIDE = 1_000_000


def round_task(task: str, r: int) -> str:
    """The name of `task`'s demonstration in round `r` (0: the paper's set, named as before)."""
    return task if r == 0 else f"{task}@{r + 1}"


def record_demo(
    task: str, goal_text: str, seed: int, world: World, full_scene: bool = False
) -> Demo | None:
    """Run the oracle on one task in `world`; the demonstration, or None if the episode
    failed."""
    goal = parse_goal(goal_text, world=world)
    others = tuple(t for t in world.object_types if t not in goal.objects) if full_scene else ()
    states: list[SymbolicSceneGraph] = []
    actions: list[str] = []

    def on_step(record, obs) -> None:
        if record is not None and record.status != "success":
            return  # a primitive that failed and changed nothing is no transition
        if record is not None:
            actions.append(record.action)
        states.append(obs.symbols.state)

    result = run_episode(
        KitchenStorageEnv(visuals=False, world=world),
        make_agent("oracle"),
        goal,
        seed,
        on_step=on_step,
        others=others,
    )
    if not result.success or not actions or any(s.status != "success" for s in result.steps):
        return None  # a failure, a detour, or a goal that held from the start shows nothing
    return Demo(
        task,
        goal_text,
        seed,
        ResetOptions(goal, others=others).objects(),
        tuple(actions),
        tuple(tuple(str(lit) for lit in s.sorted_literals()) for s in states),
        world=world,
    )


def _recorded(
    out: Path, seed: int, full_scene: bool, scene: str | None, world: World
) -> dict[str, Demo]:
    """The demonstrations already in `out`, by task; a set made with another seed, scene of
    objects or scene file refused."""
    meta_path = out / META
    if meta_path.exists():
        saved = read_json(meta_path, "demonstration metadata")
        if saved.get("seed") != seed or saved.get("version") != VERSION:
            raise InvalidInputError(f"'{out}' holds demonstrations made with another seed")
        if saved.get("full_scene", False) != full_scene:
            scene = "every object type" if saved.get("full_scene") else "their goal's objects alone"
            raise InvalidInputError(f"'{out}' holds demonstrations recorded in a scene of {scene}")
        if saved.get("scene") != scene:
            where = saved.get("scene") or "the kitchen"
            raise InvalidInputError(f"'{out}' holds demonstrations recorded in {where}")
    return {d.task: d for d in read_demos(out / DEMOS, world, tolerate_cut=True)}


def collect_demos(
    out: Path,
    seed: int,
    command: str = "",
    on_demo: Callable[[Demo], None] | None = None,
    full_scene: bool = False,
    rounds: int = 1,
    on_start: Callable[[int], None] | None = None,
    scene: Path | None = None,
) -> list[Demo]:
    """Record every task of every round not yet in `out` (appending as each finishes); all
    demos, round by round in task order. `on_start` hears how many are already recorded.
    `scene`: record them in this scene file's world (default: the kitchen), which `meta.json`
    keeps (`data.demos.demos_world`)."""
    if rounds < 1:
        raise InvalidInputError(f"rounds {rounds}: need at least 1")
    world, where = (default_world(), None) if scene is None else (read_world(scene), str(scene))
    if scene is not None:
        for _, goal in TASKS:
            try:
                parse_goal(goal, world=world)
            except InvalidInputError as e:
                raise InvalidInputError(
                    f"--scene {scene}: the demonstration tasks name the kitchen's groceries "
                    f"and shelves ({e})"
                ) from None
    check_own(out, META, "demonstration set")  # never into another command's folder
    meta = {"format": FORMAT, "version": VERSION, "seed": seed, "command": command}
    if full_scene:
        meta["full_scene"] = True
    if rounds > 1:
        meta["rounds"] = rounds
    if where is not None:  # a kitchen set records no scene, as before scenes were given
        meta["scene"] = where
    meta_path = out / META
    _recorded(out, seed, full_scene, where, world)
    hold_folder(out)  # one writer: a second collection into `out` is refused
    done = _recorded(out, seed, full_scene, where, world)  # again, now that the folder is ours
    saved = read_json(meta_path, "demonstration metadata") if meta_path.exists() else {}
    if saved.get("rounds", 1) < rounds or not saved:  # a set grown by more rounds says so
        write_atomically(meta_path, json.dumps(meta, indent=2) + "\n")
    path = out / DEMOS
    if path.exists() and path.stat().st_size and not path.read_bytes().endswith(b"\n"):
        with open(path, "a") as f:  # a line cut short by an interruption: end it
            f.write("\n")
    order = [(r, i, round_task(t, r), g) for r in range(rounds) for i, (t, g) in enumerate(TASKS)]
    if on_start:
        on_start(sum(task in done for _, _, task, _ in order))
    for r, i, task, goal in order:
        if task in done:
            continue
        base = seed * 1000 + r * ROUND_STRIDE + i * RETRIES
        for attempt in range(RETRIES):
            demo = record_demo(task, goal, base + attempt, world, full_scene)
            if demo is not None:
                break
        else:
            raise RuntimeError(f"task {task}: the oracle failed {RETRIES} times")
        with open(path, "a") as f:
            f.write(json.dumps(demo.to_json()) + "\n")
        done[task] = demo
        if on_demo:
            on_demo(demo)
    return [done[t] for _, _, t, _ in order]
