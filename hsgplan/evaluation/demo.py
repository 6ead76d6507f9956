"""One episode with pictures: a GIF from the fixed camera, a drawing of the symbolic scene
graph at every step, and `episode.json` (seed, goal, actions, outcomes, timings)."""

from __future__ import annotations

import json
import random
from pathlib import Path

import imageio.v3 as iio

from hsgplan.agents.registry import make_agent
from hsgplan.domain.goals import Goal
from hsgplan.evaluation.episode import EpisodeRecord, run_episode
from hsgplan.sim.env import KitchenStorageEnv
from hsgplan.sim.render import Camera
from hsgplan.symbolic.generator import random_goal
from hsgplan.viz.scene_graph_drawing import draw_symbolic

FRAME_EVERY = 6  # arm waypoints between two GIF frames
HOLD = 4  # frames a step's end state stays on screen


def demo_goal(objects: int, seed: int) -> Goal:
    return random_goal(objects, random.Random(f"demo-{seed}"), stacking=objects > 2)


def run_demo(agent_name: str, goal: Goal, seed: int, out: Path) -> EpisodeRecord:
    """Run the episode and write its pictures and record into `out`."""
    out.mkdir(parents=True, exist_ok=True)
    graphs = out / "graphs"
    graphs.mkdir(exist_ok=True)
    env = KitchenStorageEnv(camera=Camera(width=320, height=240))
    frames = []
    waypoints = 0

    def on_frame() -> None:
        nonlocal waypoints
        waypoints += 1
        if waypoints % FRAME_EVERY == 0:
            frames.append(env.render())

    def on_step(record, obs) -> None:
        frames.extend([env.render()] * HOLD)
        k = 0 if record is None else record.step
        title = "start" if record is None else f"step {k}: {record.params} -> {record.status}"
        draw_symbolic(obs.symbols.state, graphs / f"step_{k:02d}.png", title, goal)

    record = run_episode(env, make_agent(agent_name), goal, seed, on_frame, on_step)
    iio.imwrite(out / "episode.gif", frames, duration=80, loop=0)
    (out / "episode.json").write_text(json.dumps(record.to_json(), indent=2) + "\n")
    return record
