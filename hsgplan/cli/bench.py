"""`hsgplan bench ...`: speed, as medians over one run."""

from __future__ import annotations

import json
from typing import Annotated

import typer
from rich.progress import Progress

from hsgplan.agents.registry import DEFAULT_SEARCH, SEARCH_BASELINES
from hsgplan.cli.common import (
    MarkdownFlag,
    PerceptionCheckpoint,
    RayAddress,
    RunFolder,
    SceneFiles,
    SceneOption,
    Summaries,
    TaskCheckpoint,
    bounded_option,
    check_ray,
    choice,
    default_networks,
    err,
    in_scene,
    out,
    parse_sizes,
    print_table,
    refuses_bad_input,
    scene_world,
    shown,
)
from hsgplan.cli.seeding import SeedOrSplitStart, SplitOption, split_seed
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.world import MAX_OBJECTS
from hsgplan.paths import RUNS, TASK_CHECKPOINT

app = typer.Typer(
    cls=Summaries,
    no_args_is_help=True,
    help="Measure speed (medians over one run) and what the motion constants rest on.",
)
SearchName = choice("SearchName", SEARCH_BASELINES)
DEFAULT_SEARCH_NAME = SearchName(DEFAULT_SEARCH)


@app.command("sim")
@refuses_bad_input
def bench_sim(
    sizes: Annotated[str, typer.Option(help="Problem sizes.")] = "2-6",
    episodes: Annotated[int, bounded_option("episodes", "Oracle episodes per size.")] = 5,
    seed: Annotated[int, bounded_option("seed", "Random seed.")] = 0,
    markdown: MarkdownFlag = False,
    scene: SceneFiles = None,
) -> None:
    """Median seconds per primitive (motion planning included) and per oracle episode."""
    from hsgplan.benchmarks.sim import bench_sim as run
    from hsgplan.domain.scene_file import read_worlds

    size_list = parse_sizes(sizes)
    where = None if scene is None else str(scene)
    files = 1 if scene is None else len(read_worlds(scene))  # each read: a bad one refused
    with Progress(console=err, transient=True) as progress:
        task = progress.add_task("oracle episodes", total=len(size_list) * episodes * files)
        rows = run(size_list, episodes, seed, lambda r: progress.advance(task), where)
    cells = [
        (r.what, str(r.samples), "—" if r.median_seconds is None else f"{r.median_seconds:.3f}")
        for r in rows
    ]
    print_table(
        f"Simulation speed, one core (seed {seed}{in_scene(scene)})",
        ("what", "samples", "median s"),
        cells,
        markdown,
    )


@app.command("symbolic")
@refuses_bad_input
def bench_symbolic(
    sizes: Annotated[str, typer.Option(help="Problem sizes, e.g. 2-12.")] = "2-12",
    goals: Annotated[int, bounded_option("goals", "Goals per size.")] = 20,
    seed: Annotated[int, bounded_option("seed", "Random seed.")] = 0,
    optimal_max_size: Annotated[
        int,
        typer.Option(
            help="Largest size the optimal search is timed on (0: none).", min=0, max=MAX_OBJECTS
        ),
    ] = 8,
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON rows.", metavar="")] = False,
    markdown: MarkdownFlag = False,
    scene: SceneOption = None,
) -> None:
    """Fast Downward plan time per size: median over the goals, both search configurations."""
    from hsgplan.benchmarks.symbolic import bench_symbolic as run

    size_list = parse_sizes(sizes)
    world = scene_world(scene)
    total = sum(goals * (2 if n <= optimal_max_size else 1) for n in size_list)
    with Progress(console=err, transient=True) as progress:
        task = progress.add_task("planning", total=total)
        rows = run(
            size_list,
            goals,
            seed,
            world,
            optimal_max_size,
            on_problem=lambda: progress.advance(task),
        )
    if as_json:
        print(json.dumps([r.to_json() for r in rows], indent=2))
        return
    where = in_scene(scene)
    title = f"Fast Downward plan time, median over {goals} goals per size (seed {seed}{where})"
    header = ("objects", "planner", "solved", "median s", "median plan length")
    cells = [
        (
            str(r.size),
            r.planner,
            f"{r.solved}/{r.problems}",
            "—" if r.median_seconds is None else f"{r.median_seconds:.3f}",
            "—" if r.median_plan_length is None else f"{r.median_plan_length:g}",
        )
        for r in rows
    ]
    print_table(title, header, cells, markdown)


@app.command("task")
@refuses_bad_input
def bench_task(
    sizes: Annotated[str, typer.Option(help="Problem sizes.")] = "2-6",
    goals: Annotated[int, bounded_option("goals", "Goals per size.")] = 20,
    seed: Annotated[int, bounded_option("seed", "Random seed.")] = 0,
    checkpoint: TaskCheckpoint = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON rows.", metavar="")] = False,
    markdown: MarkdownFlag = False,
    scene: SceneOption = None,
) -> None:
    """Task-planning time: the learned regression planner against Fast Downward, one core."""
    from hsgplan.agents.registry import check_reads
    from hsgplan.benchmarks.task import bench_task as run
    from hsgplan.planning.regression.gnn import load_network

    size_list = parse_sizes(sizes)
    world = scene_world(scene)
    given, _ = default_networks("regression+sampler", [world], checkpoint, None)
    checkpoint = given or TASK_CHECKPOINT
    load_network(checkpoint / "preimage")  # a missing checkpoint fails before any work
    check_reads([checkpoint], world, scene)
    with Progress(console=err, transient=True) as progress:
        task = progress.add_task("episodes", total=goals * len(size_list))
        rows = run(
            checkpoint,
            size_list,
            goals,
            seed,
            on_episode=lambda: progress.advance(task),
            world=world,
        )
    if as_json:
        print(json.dumps([r.to_json() for r in rows], indent=2))
        return

    def ms(v: float | None) -> str:
        return "—" if v is None else f"{v:.1f}"

    cells = [
        (
            str(r.size),
            r.planner,
            f"{r.solved}/{r.episodes}",
            ms(r.median_ms_per_decision),
            ms(r.median_ms_per_episode),
        )
        for r in rows
    ]
    print_table(
        f"Task-planning time, median over {goals} goals per size, one core (seed {seed}"
        f"{in_scene(scene)})",
        ("objects", "planner", "solved", "ms per decision", "ms per episode"),
        cells,
        markdown,
    )


@app.command("timing")
@refuses_bad_input
def bench_timing(
    sizes: Annotated[str, typer.Option(help="Problem sizes.")] = "2-6,8,10",
    goals: Annotated[
        int,
        bounded_option("goals", "Goals per size, the same for both agents."),
    ] = 10,
    seed: SeedOrSplitStart = None,
    split: SplitOption = None,
    workers: Annotated[
        int,
        bounded_option("workers", "Episodes side by side (1: nothing competes for the core)."),
    ] = 1,
    search: Annotated[
        SearchName,
        typer.Option(
            help=f"The search baseline: {', '.join(SearchName)} (docs/cli.md, Agents).",
            metavar="SEARCH",
        ),
    ] = DEFAULT_SEARCH_NAME,
    ray: RayAddress = None,
    run_dir: RunFolder = None,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print one JSON object.", metavar="")
    ] = False,
    markdown: MarkdownFlag = False,
    scene: SceneFiles = None,
) -> None:
    """The paper's Table 2: task-planning and motion seconds per episode, ours (regression +
    GNN) against a search-based baseline, on the same goals; writes table2.md, table2.png
    and summary.json into the run folder."""
    from hsgplan.agents.registry import make_agent
    from hsgplan.benchmarks.timing import (
        check_timing_folder,
        run_timing,
        tables,
        timing_agents,
        total_episodes,
    )

    size_list = parse_sizes(sizes)
    seed = split_seed(seed, split)
    split_name = split and split.value
    baseline = search.value
    agents = timing_agents(baseline)
    # the default folder of the `search` baseline keeps the name it had before the choice
    which = "" if baseline == "search" else f"-{baseline}"
    named = split_name or f"seed{seed}"
    folder = run_dir or RUNS / f"timing-s{sizes.replace(',', '_')}-g{goals}-{named}{which}"
    # cheap refusals before the agents load
    where = None if scene is None else str(scene)
    check_timing_folder(size_list, goals, seed, folder, baseline, where, split_name)
    check_ray(ray)
    for agent in agents.values():  # a missing checkpoint is refused before any work
        make_agent(agent)
    with Progress(console=err, transient=True) as progress:
        total = total_episodes(size_list, goals, seed, where, split_name)
        task = progress.add_task(f"ours, {baseline}", total=total)
        report = run_timing(
            size_list,
            goals,
            seed,
            folder,
            workers,
            lambda r: progress.advance(task),
            baseline,
            ray,
            where,
            split_name,
        )
    if as_json:
        print(json.dumps(report, indent=2))
        return
    for t in tables(report):
        print_table(t.title, t.header, [list(r) for r in t.rows], markdown)
    if not markdown:
        out.print(f"wrote {shown(folder)}/table2.md, table2.png, summary.json", highlight=False)


@app.command("collect")
@refuses_bad_input
def bench_collect(
    primitives: Annotated[str, typer.Option(help="place, push or place,push.")] = "place,push",
    samples: Annotated[int, bounded_option("samples", "Successful samples per primitive.")] = 300,
    workers: Annotated[int, bounded_option("workers", "Processes.")] = 2,
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON rows.", metavar="")] = False,
    markdown: MarkdownFlag = False,
    scene: SceneOption = None,
) -> None:
    """Successful motion samples per second of the collector (wall time, start-up included)."""
    from hsgplan.benchmarks.collect import bench_collect as run

    kinds = [p.strip() for p in primitives.split(",")]
    if "" in kinds or len(set(kinds)) != len(kinds):
        raise InvalidInputError(f"--primitives '{primitives}': name place, push or both, once")
    for p in kinds:
        if p not in ("place", "push"):
            raise InvalidInputError(f"primitive '{p}': place or push")
    rows = run(kinds, samples, workers, None if scene is None else str(scene))
    if as_json:
        print(json.dumps([r.to_json() for r in rows], indent=2))
        return
    cells = [
        (
            r.primitive,
            str(r.workers),
            str(r.samples),
            f"{r.samples / max(1, r.trials):.0%}",
            f"{r.seconds:.0f}",
            f"{r.samples_per_second:.2f}",
        )
        for r in rows
    ]
    print_table(
        f"Motion data collection speed{in_scene(scene)}",
        ("primitive", "workers", "samples", "trials successful", "seconds", "samples per s"),
        cells,
        markdown,
    )


@app.command("observe")
@refuses_bad_input
def bench_observe(
    scenes: Annotated[int, bounded_option("scenes", "Scenes staged, rendered and seen.")] = 30,
    seed: Annotated[int, bounded_option("seed", "Seed of the scenes.")] = 100,
    perception_checkpoint: PerceptionCheckpoint = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.", metavar="")] = False,
    markdown: MarkdownFlag = False,
    scene: SceneOption = None,
) -> None:
    """Seconds per look: the fixed cameras' rendering, and the observation through f_p (the
    keypoint network, PnP, fusion, naming and resting, and the tracker); medians over the
    scenes."""
    from hsgplan.benchmarks.observe import bench_observe as run
    from hsgplan.evaluation.config import unseeable
    from hsgplan.paths import perception_folder

    world = scene_world(scene)
    if why := unseeable([world], scene, perception_checkpoint):
        raise InvalidInputError(why)
    with Progress(console=err, transient=True) as progress:
        task = progress.add_task("scenes", total=scenes)
        rows = run(
            perception_folder(perception_checkpoint),
            scenes,
            seed,
            on_scene=lambda: progress.advance(task),
            world=world,
        )
    if as_json:
        print(json.dumps([r.to_json() for r in rows], indent=2))
        return
    print_table(
        f"One look in the simulated loop, one core: seconds per scene (medians), {scenes} "
        f"scenes, seed {seed}{in_scene(scene)}; the observation (f_p and the tracker) is what "
        "a real robot would pay, the rendering what the simulation adds",
        ("objects", "scenes", "render", "f_p", "tracker", "observation", "look", "look p90"),
        [
            (
                r.objects,
                str(r.scenes),
                f"{r.render_median:.3f}",
                f"{r.detect_median:.3f}",
                f"{r.track_median:.4f}",
                f"{r.observation_median:.3f}",
                f"{r.look_median:.3f}",
                f"{r.look_p90:.3f}",
            )
            for r in rows
        ],
        markdown,
    )


@app.command("start")
@refuses_bad_input
def bench_start(
    sizes: Annotated[str, typer.Option(help="Problem sizes.")] = "8,10,12",
    goals: Annotated[int, bounded_option("goals", "Goals per size.")] = 10,
    seed: SeedOrSplitStart = None,
    split: SplitOption = None,
    repairs: Annotated[
        int | None,
        typer.Option(
            help="Times a draw's objects that no grasp fits are put elsewhere before it is "
            "given up (default: the sampler's; 0: drawn again at once).",
            min=0,
            max=10,
        ),
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON rows.", metavar="")] = False,
    markdown: MarkdownFlag = False,
    scene: SceneOption = None,
) -> None:
    """Draws and seconds per start scene, and the scenes that could not be drawn, on the goals
    and episode seeds `eval world` runs with the same sizes, goals, seed and split."""
    from hsgplan.benchmarks.start_scenes import bench_start as run

    size_list = parse_sizes(sizes)
    seed = split_seed(seed, split)
    scene_world(scene)  # a bad scene file: refused before anything is drawn
    with Progress(console=err, transient=True) as progress:
        task = progress.add_task("start scenes", total=len(size_list) * goals)
        rows = run(
            size_list,
            goals,
            seed,
            split and split.value,
            None if scene is None else str(scene),
            lambda: progress.advance(task),
            repairs,
        )
    repairs = rows[0].repairs if rows else repairs
    if as_json:
        print(json.dumps([r.to_json() for r in rows], indent=2))
        return
    cells = [
        (
            str(r.objects),
            str(r.scenes),
            str(r.unsampled),
            f"{r.draws_median:g}",
            str(r.draws_max),
            str(r.draws_total),
            f"{r.seconds_median:.1f}",
        )
        for r in rows
    ]
    where = f"{split.value} split" if split else "exploration"
    print_table(
        f"Start scenes, one core: draws per scene, {repairs} repairs a draw (seed {seed}, "
        f"{where}{in_scene(scene)})",
        ("objects", "scenes", "unsampled", "draws median", "draws max", "draws total", "median s"),
        cells,
        markdown,
    )
