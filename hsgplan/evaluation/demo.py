"""One episode with pictures: a GIF from two cameras with the current step and subgoal written
on every frame, a drawing of the symbolic scene graph at every step, and `episode.json` (seed,
goal, every decision with its subgoal, parameters, outcome and timings); asked for, a rerun
recording (`evaluation.recording`)."""

from __future__ import annotations

import json
import random
import shutil
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import imageio.v3 as iio
import numpy as np

from hsgplan.agents.base import Agent, Decision
from hsgplan.agents.registry import make_agent
from hsgplan.domain.goals import Goal
from hsgplan.domain.scene import World
from hsgplan.domain.world import MAX_STEPS
from hsgplan.evaluation.episode import EpisodeRecord, StepRecord, params_text, run_episode
from hsgplan.files import atomic, write_atomically
from hsgplan.runner.engines import one_core
from hsgplan.sim.env import KitchenStorageEnv
from hsgplan.sim.observer import CameraObserver, SceneObserver
from hsgplan.sim.render import DEMO_VIEWS
from hsgplan.symbolic.generator import random_goal
from hsgplan.viz.frames import compose
from hsgplan.viz.scene_graph_drawing import draw_symbolic

FRAME_EVERY = 12  # arm waypoints between two GIF frames
HOLD = 5  # frames a step's end state stays on screen


def demo_goal(objects: int, seed: int, world: World) -> Goal:
    return random_goal(objects, random.Random(f"demo-{seed}"), stacking=objects > 2, world=world)


def run_demo(
    agent: str | Agent,
    goal: Goal,
    seed: int,
    out: Path,
    on_step: Callable[[StepRecord], None] | None = None,
    scale: float = 1.0,
    frame_every: int = FRAME_EVERY,
    observer: SceneObserver | CameraObserver | None = None,
    end_at_failure: bool = False,
    recording: Path | None = None,
) -> EpisodeRecord:
    """Run the episode and write its pictures and record into `out`; `on_step` sees every
    step as soon as it has been executed; `end_at_failure` as `run_episode` takes it.

    Args:
        agent: a registered agent's name (its shipped checkpoints), or the agent itself.
        scale: the GIF's frames at this fraction of their size (a report keeps them small).
        frame_every: arm waypoints between two frames.
        observer: what the agent sees with (default: the ground truth). Another observer's
            estimate, as of its last observation, is drawn on the views as cuboids.
        recording: also write the episode as a rerun recording there (`.rrd`; needs the
            `rerun` extra): the true scene and the belief, the cameras, every decision.
    """
    one_core()  # beside other busy processes, two threads make each planner call 20x slower
    out.mkdir(parents=True, exist_ok=True)
    graphs = out / "graphs"
    # a demo folder holds one episode: an earlier one's step drawings would mix with these
    shutil.rmtree(graphs, ignore_errors=True)
    graphs.mkdir()
    rec = None
    if recording is not None:
        from hsgplan.evaluation.recording import EpisodeRecording, RecordedLooks

        rec = EpisodeRecording(recording, str(goal), seed)
        if isinstance(observer, CameraObserver):
            observer = RecordedLooks(observer, rec)
    env = KitchenStorageEnv(observer=observer, world=goal.world)
    seeing = observer is not None and observer.name != "gt"
    believed: dict = {}
    frames = []
    waypoints = 0
    caption = ["start", "", f"goal: {goal}"]

    panels = [
        [replace(c, width=round(c.width * scale), height=round(c.height * scale)) for c in cams]
        for _, cams in DEMO_VIEWS
    ]

    def view(camera):
        image = env.render(camera)
        if seeing:
            from hsgplan.perception.draw import draw_cuboids

            image = draw_cuboids(image, camera, believed, goal.world)
        return image

    def snapshot():
        # a panel of several cameras stacks their pictures, top to bottom
        views = [np.vstack([view(c) for c in cams]) for cams in panels]
        return compose(views, [name for name, _ in DEMO_VIEWS], caption, scale)

    def on_frame() -> None:
        nonlocal waypoints
        waypoints += 1
        if rec is not None:
            rec.on_frame()
        if waypoints % frame_every == 0:
            frames.append(snapshot())

    def on_decide(step: int, d: Decision) -> None:
        caption[:] = [
            f"step {step} (of at most {MAX_STEPS}): {params_text(d.params)}",
            f"subgoal: {d.subgoal}",
            f"goal: {goal}",
        ]
        if rec is not None:
            rec.decide(step, d, params_text(d.params))

    def on_step_done(record, obs) -> None:
        believed.clear()
        held = obs.scene_graph.held
        believed.update({n.name: n.pose for n in obs.scene_graph.nodes if n.name != held})
        if record is not None:
            caption[0] += f"  ->  {record.status}"
        if goal.satisfied_by(obs.symbols.state):
            caption[0] += "   |   the goal holds"
        frames.extend([snapshot()] * HOLD)
        k = 0 if record is None else record.step
        title = "start" if record is None else f"step {k}: {record.params} -> {record.status}"
        draw_symbolic(obs.symbols.state, graphs / f"step_{k:02d}.png", title, goal)
        if rec is not None and record is None:
            rec.start(env, obs)
        elif rec is not None:
            rec.stepped(record, obs)
        if record is not None and on_step:
            on_step(record)

    if isinstance(agent, str):
        agent = make_agent(agent)
    try:
        record = run_episode(
            env, agent, goal, seed, on_frame, on_step_done, on_decide, end_at_failure
        )
    finally:
        if rec is not None:
            rec.close()
    with atomic(out / "episode.gif") as tmp:
        iio.imwrite(tmp, frames, duration=90, loop=0)
    write_atomically(out / "episode.json", json.dumps(record.to_json(), indent=2) + "\n")
    return record
