"""Scenes from inside the loop, for scoring f_p where the agent uses it: the oracle agent
(Fast Downward and the geometric sampler) runs a random goal of 2 to 6 objects for a random
number of steps (1 to `MAX_STEPS_INTO`, fewer where the goal holds sooner), and the scene is
taken as it stands then: objects stacked, pushed into a shelf, put down where a primitive left
them, one in the hand. The fixed cameras render it with the scene's own look, as the rgb
observer sees it; the object in the hand is left out of the truth (the robot knows where its
hand is). An episode that ends on a failure before gives no scene.

The same seed gives the same scenes. Goals and step counts come from `random.Random(seed)`
drawn per scene, the episodes' seeds from them.
"""

from __future__ import annotations

import contextlib
import random
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import numpy as np

from hsgplan.agents.registry import make_agent
from hsgplan.domain.checks import MAX_SEED
from hsgplan.domain.world import World
from hsgplan.evaluation.episode import run_episode
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.env import KitchenStorageEnv
from hsgplan.sim.render import Camera
from hsgplan.sim.sensing import Box
from hsgplan.symbolic.generator import random_goals

MAX_STEPS_INTO = 10
SIZES = (2, 6)


@dataclass(frozen=True)
class LoopScene:
    truth: dict[str, Pose]  # every object not in the hand
    held: Pose | None  # the object in the hand, if any
    images: np.ndarray  # [V, H, W, 3]
    step: int  # steps run before it was taken
    world: World  # the scene's
    arm: tuple[Box, ...] = ()  # the arm's links (what the robot knows of where its arm is)


class _Taken(Exception):
    pass


def loop_scenes(
    scenes: int, seed: int, cameras: tuple[Camera, ...], worlds: Sequence[World]
) -> Iterator[LoopScene]:
    """`scenes` scenes, each from an episode of its own, scene k in `worlds[k % len(worlds)]`."""
    envs = {id(w): KitchenStorageEnv(world=w) for w in worlds}
    agent = make_agent("oracle")
    try:
        for index in range(scenes):
            world = worlds[index % len(worlds)]
            env = envs[id(world)]
            rng = random.Random(f"{seed}/{index}")
            goal = random_goals(rng.randint(*SIZES), 1, rng.randrange(MAX_SEED), world=world)[0]
            wanted = rng.randint(1, MAX_STEPS_INTO)
            steps = _run_into(env, agent, goal, rng.randrange(MAX_SEED), wanted)
            scene = env.scene
            if scene is None:  # the episode ended on a failure before: no scene to take
                continue
            held = scene.held()
            poses = scene.poses()
            images = np.stack([c.capture(scene.bc) for c in cameras])
            truth = {o: p for o, p in poses.items() if o != held}
            arm = scene.robot.boxes()
            yield LoopScene(truth, poses[held] if held else None, images, steps, world, arm)
    finally:
        for env in envs.values():
            env.close()


def _run_into(env: KitchenStorageEnv, agent, goal, seed: int, wanted: int) -> int:
    """Run the episode until `wanted` steps have run or the goal holds, its scene left open;
    the steps run."""
    steps = [0]

    def stop(record, obs) -> None:
        steps[0] = 0 if record is None else record.step
        if steps[0] >= wanted or (record is not None and goal.satisfied_by(obs.symbols.state)):
            raise _Taken

    with contextlib.suppress(_Taken):
        run_episode(env, agent, goal, seed, on_step=stop)
    return steps[0]
