"""Commands of the simulated world: demo, eval."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path
from typing import Annotated

import typer
from rich.progress import Progress

from hsgplan.agents.registry import PAPER_LIKE, agent_name, agent_parts
from hsgplan.cli.common import (
    AgentName,
    MotionCheckpoints,
    MotionName,
    PerceptionCheckpoint,
    PlannerName,
    ProtocolName,
    RayAddress,
    RunFolder,
    SceneFiles,
    SceneOption,
    TaskCheckpoint,
    bounded_option,
    check_ray,
    choice,
    config_default,
    config_option,
    err,
    input_path,
    out,
    out_file,
    out_folder,
    parse_sizes,
    print_table,
    refuses_bad_input,
    scene_world,
    shown,
)
from hsgplan.cli.seeding import (
    PerceptionRulesOption,
    PlanRulesOption,
    SeedOrSplitStart,
    SplitOption,
    plan_rule_settings,
    rule_settings,
    split_seed,
)
from hsgplan.domain.errors import InvalidInputError
from hsgplan.evaluation.config import OBSERVERS, TABLES, EvalConfig
from hsgplan.paths import RUNS, shipped
from hsgplan.runner.run_folder import check_own

# what each agent is: docs/cli.md, "Agents" (a test holds the two to the same names)
AGENT_HELP = f"{', '.join(AgentName)}: what each is in docs/cli.md."
LEARNED = AgentName("learned")
PerceptionName = choice("PerceptionName", OBSERVERS)
GT = PerceptionName("gt")
AgentOption = Annotated[AgentName, typer.Option(help=AGENT_HELP, metavar="AGENT")]
PlannerOption = Annotated[
    PlannerName | None,
    typer.Option(
        help=f"Task planner in place of the agent's: {', '.join(PlannerName)}.", metavar="PLANNER"
    ),
]
MotionOption = Annotated[
    MotionName | None,
    typer.Option(
        help=f"Motion generator in place of the agent's: {', '.join(MotionName)}.",
        metavar="MOTION",
    ),
]


@refuses_bad_input
def demo(
    agent: AgentOption = LEARNED,
    planner: PlannerOption = None,
    motion: MotionOption = None,
    goal: Annotated[
        str | None, typer.Option(help="Goal literals (default: a random goal).")
    ] = None,
    objects: Annotated[int, typer.Option(help="Objects in the random goal (2-12).")] = 4,
    seed: Annotated[int, bounded_option("seed", "Seed for the goal and the scene.")] = 0,
    out_dir: Annotated[
        Path, typer.Option("--out", help="Folder for the pictures.", parser=out_folder)
    ] = RUNS / "demo",
    perception: Annotated[
        PerceptionName,
        typer.Option(
            help="What the agent sees with: gt (the simulator's poses) or rgb (f_p on the "
            "fixed cameras' images; its estimate drawn on the views as cuboids).",
            metavar="PERCEPTION",
        ),
    ] = GT,
    perception_checkpoint: PerceptionCheckpoint = None,
    rerun: Annotated[
        Path | None,
        typer.Option(
            help="Also write the episode as a rerun recording (.rrd): the true scene and the "
            "belief side by side, the cameras, every decision. Needs the rerun extra.",
            parser=out_file,
        ),
    ] = None,
    scene: SceneOption = None,
    checkpoint: TaskCheckpoint = None,
    motion_checkpoints: MotionCheckpoints = None,
) -> None:
    """One episode in the simulated kitchen (or the world of --scene): a GIF, a scene-graph
    drawing per step, a record; with --rerun, a 3D recording for rerun's viewer."""
    from hsgplan.agents.goal_scope import check_goal
    from hsgplan.agents.registry import default_checkpoints, make_agent
    from hsgplan.domain.goals import parse_goal
    from hsgplan.evaluation.config import check_seen
    from hsgplan.evaluation.demo import demo_goal, run_demo
    from hsgplan.evaluation.observers import make_observer
    from hsgplan.evaluation.protocol import check_agent_world
    from hsgplan.symbolic.generator import check_size

    agent = agent_name(agent.value, planner and planner.value, motion and motion.value)
    world = scene_world(scene)
    *folders, swapped = default_checkpoints(
        agent,
        [world],
        checkpoint and shipped(checkpoint),
        motion_checkpoints and shipped(motion_checkpoints),
    )
    if swapped:
        err.print(swapped, highlight=False)
    check_agent_world(agent, world, scene, *folders)
    check_seen(perception.value, [world], scene, perception_checkpoint)
    made = make_agent(agent, *folders)  # an unknown name or a missing checkpoint: before work
    observer = make_observer(
        perception.value, perception_checkpoint and shipped(perception_checkpoint)
    )
    if goal is None:
        check_size(objects)
    g = parse_goal(goal, world=world) if goal else demo_goal(objects, seed, world)
    check_goal(agent, g)
    check_own(out_dir, "episode.json", "demo")
    if rerun is not None:
        check_recording(rerun)
    out.print(
        f"[bold]goal[/] ({g.size} objects, seed {seed}, agent {agent}): {g}",
        highlight=False,
        soft_wrap=True,
    )
    record = run_demo(
        made, g, seed, out_dir, on_step=_print_step, observer=observer, recording=rerun
    )
    verdict = "[green]success[/]" if record.success else f"[red]failed: {shown(record.failure)}[/]"
    out.print(
        f"{verdict} in {len(record.steps)} steps ({record.seconds:.0f} s with the pictures); "
        f"subgoal completion {record.subgoal_completion:.2f}"
    )
    # the judge read each step on the simulator's state once the episode was over
    for s in record.steps:
        if s.truth and s.truth != s.status:
            why = f" ({s.truth_detail})" if s.truth_detail else ""
            out.print(f"the judge: step {s.step} truly {s.truth}{why}", highlight=False)
    out.print(f"wrote {shown(out_dir)}/episode.gif, graphs/, episode.json")
    if rerun is not None:
        out.print(f"wrote {shown(rerun)}: open it with `rerun {shown(rerun)}`", highlight=False)


def check_recording(path: Path) -> None:
    """A recording is asked for where rerun-sdk is installed, into a `.rrd` file."""
    from hsgplan.evaluation.recording import available

    if path.suffix != ".rrd":
        raise InvalidInputError(f"--rerun {shown(path)}: a recording's file ends in .rrd")
    if not available():
        raise InvalidInputError(NO_RERUN)


NO_RERUN = "--rerun needs rerun-sdk: pip install -e '.[rerun]' (make installs it)"


def _print_step(s) -> None:
    """A step in three lines, each within 80 columns however long its parameters: the subgoal
    and what became of it, the parameters, the time each level took."""
    times = (
        f"task {s.task_seconds * 1000:.1f} ms, motion {s.motion_seconds * 1000:.1f} ms, "
        f"execution {s.execution_seconds:.2f} s"
    )
    for line in (f"{s.step:>2}  {s.subgoal:<44} {s.status}", f"    {s.params}", f"    {times}"):
        out.print(line, highlight=False, markup=False, soft_wrap=True)


DEFAULT_PROTOCOL = ProtocolName(config_default(EvalConfig, "protocol"))


@refuses_bad_input
def evaluate(
    agent: AgentOption = LEARNED,
    planner: PlannerOption = None,
    motion: Annotated[
        str | None,
        typer.Option(
            help="Motion generators in place of the agent's, comma-separated (gnn,mlp,random): "
            "one column each."
        ),
    ] = None,
    sizes: Annotated[str, typer.Option(help="Problem sizes, e.g. 2-6.")] = "2-6",
    goals: Annotated[int, bounded_option("goals", "Random goals per size.")] = 50,
    repeats: Annotated[
        int,
        config_option(EvalConfig, "repeats", "Episodes per goal, each from its own scene."),
    ] = config_default(EvalConfig, "repeats"),
    seed: SeedOrSplitStart = None,
    split: SplitOption = None,
    goals_file: Annotated[
        Path | None, typer.Option(help="Goals from a file instead.", parser=input_path)
    ] = None,
    checkpoint: TaskCheckpoint = None,
    motion_checkpoints: MotionCheckpoints = None,
    perception: Annotated[
        str,
        typer.Option(
            help="What the agent sees with, comma-separated: gt (the simulator's poses), rgb "
            "(f_p on the fixed cameras' images), rgb-latest (f_p, each look taken as it "
            "comes: no steady rule), rgb-keypoint-yaw (f_p, boxes' yaws as their keypoints "
            "say: no silhouette check); one column each, a method seen through f_p named "
            "after its motion generator with -rgb appended (gnn-rgb)."
        ),
    ] = config_default(EvalConfig, "perception"),
    perception_checkpoint: PerceptionCheckpoint = None,
    protocol: Annotated[
        ProtocolName,
        typer.Option(
            help="paper (every headline table's): the first failed primitive ends the "
            "episode; recovering: it costs its step.",
            metavar="PROTOCOL",
        ),
    ] = DEFAULT_PROTOCOL,
    rules_off: Annotated[
        str,
        typer.Option(
            help="Recovery rules switched off, comma-separated (under the paper protocol only "
            "those it keeps; the names, and which: hsgplan rules).",
            metavar="RULES",
        ),
    ] = "",
    perception_rules: PerceptionRulesOption = "",
    plan_rules: PlanRulesOption = "",
    ablate_rules: Annotated[
        bool,
        typer.Option(
            "--ablate-rules",
            metavar="",
            help="Run the table with every recovery rule on, then with each off in turn "
            "(one folder each), and print what each buys.",
        ),
    ] = False,
    workers: Annotated[int, bounded_option("workers", "Episodes run side by side.")] = 2,
    run_dir: RunFolder = None,
    ray: RayAddress = None,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print one JSON object.", metavar="")
    ] = False,
    markdown: Annotated[
        bool, typer.Option("--markdown", help="Print Markdown tables (for the README).", metavar="")
    ] = False,
    shown_tables: Annotated[
        str,
        typer.Option(
            "--tables",
            help=f"The tables printed, comma-separated: {', '.join(TABLES)} (all are written).",
        ),
    ] = ",".join(TABLES),
    scene: SceneFiles = None,
) -> None:
    """Success rate and subgoal completion per problem size and method, beside the paper's
    Table 1, with the failure taxonomy and the time per level, under a protocol (paper or
    recovering); writes table1.md, table1.png and summary.json into the run folder."""
    from hsgplan.agents.registry import make_agent
    from hsgplan.evaluation.ablation import ablation_table, check_ablation, run_ablation
    from hsgplan.evaluation.config import TABLES, EvalConfig
    from hsgplan.evaluation.observers import make_observer
    from hsgplan.evaluation.protocol import checkpoints, trained
    from hsgplan.evaluation.table1 import Method, check_table, run_table, tables, total_episodes

    planner_name = planner and planner.value
    if motion is None:
        name = agent_name(agent.value, planner_name)
        methods = [Method(name, name)]
    else:
        motions = names_of(motion, "--motion", "generator")
        agents = [agent_name(agent.value, planner_name, m) for m in motions]
        # a column is named by its generator (and set beside the paper's) only where the task
        # planner is the paper's; other planners' columns carry their agent's whole name
        paper_planner = all(agent_parts(a)[0] in PAPER_LIKE for a in agents)
        methods = [
            Method(m if paper_planner else a, a) for m, a in zip(motions, agents, strict=True)
        ]
    seeing = names_of(perception, "--perception", "observer")
    methods = [
        Method(m.name if p == "gt" else f"{m.name}-{p}", m.agent, p)
        for m in methods
        for p in seeing
    ]
    config = EvalConfig(
        "",
        tuple(parse_sizes(sizes)),
        goals,
        split_seed(seed, split),
        str(goals_file) if goals_file else None,
        repeats,
        checkpoint and str(shipped(checkpoint)),
        motion_checkpoints and str(shipped(motion_checkpoints)),
        perception_checkpoint=perception_checkpoint and str(shipped(perception_checkpoint)),
        protocol=protocol.value,
        rules_off=names_of(rules_off, "--rules-off", "rule", none=True),
        perception_rules=rule_settings(perception_rules),
        plan_rules=plan_rule_settings(plan_rules),
        scene=str(scene) if scene else None,
        split=split and split.value,
    )
    config = _default_networks(config, [m.agent for m in methods])
    if config.perception_rules and seeing == ("gt",):
        raise InvalidInputError("--perception-rules: f_p's rules act only where it sees (rgb)")
    for p in seeing:  # an unknown observer, or f_p's checkpoint missing: refused before work
        make_observer(p, config.perception_checkpoint)
    total = total_episodes(methods, config)
    folder = run_dir or RUNS / (_run_name(methods, config) + ("-ablation" if ablate_rules else ""))
    check_ray(ray)
    which = names_of(shown_tables, "--tables", "table")
    if unknown := sorted(set(which) - set(TABLES)):
        raise InvalidInputError(f"--tables: no table '{unknown[0]}' ({', '.join(TABLES)})")
    if ablate_rules:  # the cheap refusals first: loading agents takes seconds
        total *= len(check_ablation(methods, config, folder))
    else:
        check_table(methods, config, folder)
    for m in methods:  # an unknown name or a missing checkpoint: refused before any work
        for c in trained(replace(config, agent=m.agent)).values():
            make_agent(m.agent, *checkpoints(c))
    run = run_ablation if ablate_rules else run_table
    with Progress(console=err, transient=True) as progress:
        task = progress.add_task(", ".join(m.agent for m in methods), total=total)
        report = run(methods, config, folder, workers, ray, lambda r: progress.advance(task))
    if as_json:
        print(json.dumps(report, indent=2))
        return
    for t in [ablation_table(report)] if ablate_rules else tables(report, which):
        print_table(t.title, t.header, [list(r) for r in t.rows], markdown)
        if not markdown:  # a Markdown table ends with its own blank line
            print()
    if not markdown and not ablate_rules:
        out.print(f"wrote {shown(folder)}/table1.md, table1.png, summary.json", highlight=False)


def names_of(text: str, option: str, what: str, none: bool = False) -> tuple[str, ...]:
    """A comma-separated list of names, each once; with `none`, '' names none."""
    if none and not text.strip():
        return ()
    names = tuple(n.strip() for n in text.split(","))
    if "" in names or len(set(names)) != len(names):
        raise InvalidInputError(f"{option} '{text}': name each {what} once, comma-separated")
    return names


def _run_name(methods, config) -> str:
    source = Path(config.goals_file).stem if config.goals_file else f"g{config.goals}"
    sizes = "-".join(map(str, config.sizes))
    agents = "_".join(
        m.agent + ("" if m.perception == "gt" else f"-{m.perception}") for m in methods
    )
    protocol = "" if config.protocol == DEFAULT_PROTOCOL.value else f"-{config.protocol}"
    protocol += "".join(f"-no_{rule}" for rule in config.rules_off)
    protocol += "".join(f"-{rule}" for rule in (*config.perception_rules, *config.plan_rules))
    where = f"-{Path(config.scene).stem}" if config.scene else ""
    seed = config.split or f"seed{config.seed}"
    return f"eval-{agents}{protocol}-s{sizes}-{source}-r{config.repeats}-{seed}{where}"


def _default_networks(config: EvalConfig, agents: list[str]) -> EvalConfig:
    """The config with the networks that read kind and size where it names no checkpoint and
    its scenes name what the shipped networks do not know (for every learned agent at once,
    or for none: a run's agents share their folders)."""
    from hsgplan.agents.registry import agent_checkpoints, default_checkpoints

    worlds = list(config.worlds().values())
    given = [config.checkpoint and Path(config.checkpoint)]
    given.append(config.motion_checkpoints and Path(config.motion_checkpoints))
    learned = [a for a in agents if agent_checkpoints(a)]
    swaps = [default_checkpoints(a, worlds, *given) for a in learned]
    if not learned or not all(said for *_, said in swaps):
        return config
    task, motion, said = swaps[0]
    err.print(said, highlight=False)
    return replace(config, checkpoint=str(task), motion_checkpoints=str(motion))
