"""`hsgplan collect ...`: datasets the learned models are trained on."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Annotated

import typer
from rich.progress import Progress

from hsgplan.cli.common import (
    CollectWorkers,
    MotionCheckpoints,
    RayAddress,
    SceneFiles,
    SceneOption,
    SceneRound,
    Summaries,
    TaskCheckpoint,
    bounded_option,
    check_ray,
    config_default,
    config_option,
    default_networks,
    err,
    out,
    out_folder,
    parse_sizes,
    refuses_bad_input,
    scene_worlds,
    shown,
)
from hsgplan.collect.images import ImagesConfig
from hsgplan.collect.motion import CollectConfig
from hsgplan.paths import RUNS

app = typer.Typer(cls=Summaries, no_args_is_help=True, help="Collect datasets (resumable).")
CollectionFolder = Annotated[
    Path,
    typer.Option("--out", help="Collection folder (resumed if it exists).", parser=out_folder),
]


@app.command("demos")
@refuses_bad_input
def demos(
    seed: Annotated[int, bounded_option("seed", "Seed of the demonstration scenes.")] = 0,
    out_dir: Annotated[
        Path,
        typer.Option("--out", help="Dataset folder (resumed if it exists).", parser=out_folder),
    ] = RUNS / "collect-demos",
    full_scene: Annotated[
        bool,
        typer.Option(
            "--full-scene",
            help="Record each in a scene of one object of every type, not of the goal's alone.",
        ),
    ] = False,
    rounds: Annotated[
        int,
        typer.Option(
            min=1,
            max=1000,
            help="Record the 18 tasks this many times, each in scenes of its own (a larger set "
            "for a learning curve; the first round is the paper's set).",
        ),
    ] = 1,
    scene: SceneOption = None,
) -> None:
    """Record the paper's 18 short demonstrations with the oracle in the simulated world."""
    from hsgplan.collect.demos import collect_demos
    from hsgplan.data.demos import TASKS

    command = f"hsgplan collect demos --seed {seed} --out {out_dir}"
    command += " --full-scene" * full_scene + f" --rounds {rounds}" * (rounds > 1)
    command += f" --scene {scene}" * (scene is not None)
    with Progress(console=err, transient=True) as progress:
        task = progress.add_task("demonstrations", total=len(TASKS) * rounds)
        done = collect_demos(
            out_dir,
            seed,
            command,
            lambda d: progress.advance(task),
            full_scene=full_scene,
            rounds=rounds,
            on_start=lambda n: progress.update(task, completed=n),  # a resumed set starts there
            scene=scene,
        )
        progress.update(task, completed=len(TASKS) * rounds)
    steps = sum(len(d.actions) for d in done)
    out.print(f"{len(done)} demonstrations, {steps} transitions, in {shown(out_dir)}")


def _collect_command(primitive: str, default_samples: int):
    """`collect place` and `collect push`: the same options, their own default size."""

    @refuses_bad_input
    def command(
        samples: Annotated[
            int, bounded_option("samples", "Successful trials to collect.")
        ] = default_samples,
        workers: CollectWorkers = config_default(CollectConfig, "workers"),
        seed: Annotated[
            int, config_option(CollectConfig, "seed", "Seed of the scene and parameter stream.")
        ] = config_default(CollectConfig, "seed"),
        ray: RayAddress = None,
        out_dir: Annotated[
            Path,
            typer.Option(
                "--out",
                help="Dataset folder (default: runs/collect-motion; the shipped data/motion "
                "is never written unless named).",
                parser=out_folder,
            ),
        ] = RUNS / "collect-motion",
        tasks_per_chunk: Annotated[
            int, config_option(CollectConfig, "tasks_per_chunk", "Tasks per unit of work.")
        ] = config_default(CollectConfig, "tasks_per_chunk"),
        scene: SceneRound = None,
        fell_short: Annotated[
            float,
            config_option(
                CollectConfig,
                "fell_short",
                "Pushes: the chance that a can starts where a short push left it.",
            ),
        ] = config_default(CollectConfig, "fell_short"),
    ) -> None:
        check_ray(ray)
        where = None if scene is None else str(scene)
        settings = (samples, workers, seed, ray, out_dir, tasks_per_chunk, where, fell_short)
        _collect(primitive, *settings)

    command.__doc__ = (
        f"Self-supervised {primitive} data: uniformly sampled bins tried in generated scenes."
    )
    return command


# The paper's dataset sizes.
app.command("place")(_collect_command("place", 14573))
app.command("push")(_collect_command("push", 8000))


def _collect(
    primitive: str,
    samples: int,
    workers: int,
    seed: int,
    ray,
    out_dir: Path,
    chunk: int,
    scene: str | None,
    fell_short: float,
):
    from hsgplan.collect.motion import collect
    from hsgplan.domain.parameters import MotionPrimitive

    kind = MotionPrimitive(primitive)
    config = CollectConfig(kind, samples, seed, workers, ray, chunk, scene, fell_short)
    with Progress(console=err, transient=True) as progress:
        bar = progress.add_task(f"{primitive} samples", total=samples)
        summary = collect(config, out_dir, lambda n: progress.update(bar, completed=n))
    out.print(
        f"{summary.samples} {primitive} samples from {summary.trials} trials "
        f"({summary.samples / max(1, summary.trials):.0%} successful; {summary.chunks_run} "
        f"chunks run now, {summary.unstaged} scenes not staged) in {shown(summary.dataset)}"
    )


@app.command("images")
@refuses_bad_input
def images(
    samples: Annotated[
        int, bounded_option("samples", "Samples to render (scenes x views).")
    ] = 2000,
    seed: Annotated[
        int, config_option(ImagesConfig, "seed", "Seed of the scenes and their looks.")
    ] = config_default(ImagesConfig, "seed"),
    workers: CollectWorkers = 2,
    ray: RayAddress = None,
    out_dir: CollectionFolder = RUNS / "collect-images",
    p_elsewhere: Annotated[
        float,
        config_option(
            ImagesConfig,
            "p_elsewhere",
            "Chance that an object starts off the open space (more: more stacks).",
        ),
    ] = config_default(ImagesConfig, "p_elsewhere"),
    views: Annotated[
        int | None,
        typer.Option(
            help="The first this many fixed views (3: the shoulder and front views; default: all).",
            min=1,
        ),
    ] = None,
    scene: SceneOption = None,
) -> None:
    """Synthetic training images for f_p: random scenes from the fixed cameras, domain
    randomised, with every object's pose and cuboid keypoints (format: perception/images.py)."""
    from hsgplan.collect.images import collect_images

    check_ray(ray)
    where = None if scene is None else str(scene)
    config = ImagesConfig(samples, seed, p_elsewhere=p_elsewhere, scene=where)
    if views is not None:
        config = replace(config, views=views)
    with Progress(console=err, transient=True) as progress:
        bar = progress.add_task("image chunks", total=config.chunks)
        rows = collect_images(config, out_dir, workers, ray, lambda _: progress.advance(bar))
    kept = sum(r["samples"] for r in rows)
    out.print(f"{kept} samples ({len(rows)} chunks) in {shown(out_dir)}")


@app.command("reach")
@refuses_bad_input
def reach(
    states: Annotated[
        int,
        bounded_option("states", "Staged states (a rerun may ask for more)."),
    ] = 4000,
    seed: Annotated[int, bounded_option("seed", "Seed of the states and actions.")] = 0,
    workers: CollectWorkers = 2,
    ray: RayAddress = None,
    out_dir: CollectionFolder = RUNS / "collect-reach",
    scene: SceneRound = None,
) -> None:
    """Self-supervised reachability: primitives executed in the simulated world from staged
    symbolic states, and what the world showed after each (f_reach's labels)."""
    from hsgplan.collect.reach import collect_reach

    check_ray(ray)
    with Progress(console=err, transient=True) as progress:
        bar = progress.add_task("staged states", total=states)
        summary = collect_reach(
            out_dir, states, seed, workers, ray, lambda _: progress.advance(bar), scene=scene
        )
    statuses = ", ".join(f"{k} {v}" for k, v in summary.by_status.items())
    out.print(
        f"{summary.trials} primitives executed from {summary.staged} of {summary.states} "
        f"states ({statuses or 'none'}); {summary.ran} run now in "
        f"{summary.seconds:.1f} s; in {shown(out_dir)}",
        highlight=False,
        soft_wrap=True,
    )


@app.command("visited")
@refuses_bad_input
def visited(
    episodes: Annotated[
        int, bounded_option("episodes", "Episodes per size (a rerun may ask for more).")
    ] = 120,
    sizes: Annotated[str, typer.Option(help="Goal sizes, e.g. 2-6,8.")] = "2-6,8",
    seed: Annotated[int, bounded_option("seed", "Seed of the goals, scenes and actions.")] = 0,
    workers: CollectWorkers = 2,
    ray: RayAddress = None,
    out_dir: CollectionFolder = RUNS / "collect-visited",
    checkpoint: TaskCheckpoint = None,
    motion_checkpoints: MotionCheckpoints = None,
    scene: SceneFiles = None,
) -> None:
    """f_reach's labels from the states the learned agent visits: in each, before it decides,
    primitives are executed as `collect reach` executes them from a staged state."""
    from hsgplan.collect.visited import AGENT as VISITING_AGENT
    from hsgplan.collect.visited import collect_visited

    check_ray(ray)
    size_list = tuple(parse_sizes(sizes))
    checkpoint, motion_checkpoints = default_networks(
        VISITING_AGENT, scene_worlds(scene), checkpoint, motion_checkpoints
    )
    with Progress(console=err, transient=True) as progress:
        bar = progress.add_task("episodes", total=episodes * len(set(size_list)))
        summary = collect_visited(
            out_dir,
            episodes,
            size_list,
            seed,
            workers,
            ray,
            lambda _: progress.advance(bar),
            checkpoint,
            scene=scene,
            motion_checkpoints=motion_checkpoints,
        )
    statuses = ", ".join(f"{k} {v}" for k, v in summary.by_status.items())
    out.print(
        f"{summary.trials} primitives executed from {summary.states} states of "
        f"{summary.episodes} episodes ({statuses or 'none'}); {summary.ran} run now in "
        f"{summary.seconds:.1f} s; in {shown(out_dir)}",
        highlight=False,
        soft_wrap=True,
    )
