"""Agents, task planners and motion generators by name, as the CLI offers them.

An agent is a task planner and a motion generator (`HierarchicalAgent`). The registered agents
are named pairs; any other pair is named `PLANNER+MOTION` (`regression+mlp`: the CLI's
`--planner` and `--motion`). The
search-based baselines plan both levels together and are agents of their own (`search`;
`stream`, PDDLStream's incremental algorithm; `stream-goal`, the same with goal-directed
streams; `stream-focused` and `stream-focused-goal`, PDDLStream's focused algorithm).
Shipped checkpoints are found as `hsgplan.paths` finds them, wherever the command runs.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.recovery import ALL_RULES, RecoveryRules
from hsgplan.paths import MOTION_CHECKPOINTS, TASK_CHECKPOINT

if TYPE_CHECKING:  # the names are read by the CLI's --help, which should not load torch
    from hsgplan.agents.base import Agent
    from hsgplan.domain.scene import World
    from hsgplan.motion.interface import MotionGenerator
    from hsgplan.planning.base import TaskPlanner


def _regression(checkpoint: Path, rules: RecoveryRules) -> TaskPlanner:
    from hsgplan.planning.regression.planner import RegressionPlanner

    return RegressionPlanner(checkpoint, rules=rules)


def _regression_ahead(checkpoint: Path, rules: RecoveryRules) -> TaskPlanner:
    from hsgplan.planning.regression.planner import RegressionPlanner

    return RegressionPlanner(checkpoint, rules=rules, look_ahead=True)


def _regression_parts(name: str, **parts: bool) -> Callable[[Path, RecoveryRules], TaskPlanner]:
    def make(checkpoint: Path, rules: RecoveryRules) -> TaskPlanner:
        from hsgplan.planning.regression.planner import Loop, RegressionPlanner

        planner = RegressionPlanner(checkpoint, rules=rules, loop=Loop(**parts))
        planner.name = name
        return planner

    return make


def _regression_paper(checkpoint: Path, rules: RecoveryRules) -> TaskPlanner:
    from hsgplan.planning.regression.paper_loop import PaperRegressionPlanner

    return PaperRegressionPlanner(checkpoint)


def _forward(checkpoint: Path, rules: RecoveryRules) -> TaskPlanner:
    from hsgplan.planning.regression.forward import ForwardPlanner

    return ForwardPlanner(checkpoint)


def _fast_downward(checkpoint: Path, rules: RecoveryRules) -> TaskPlanner:
    from hsgplan.planning.fast_downward import FastDownwardTaskPlanner

    return FastDownwardTaskPlanner()


# name -> factory of a task planner from the learned planner's checkpoint folder and the
# recovery rules in force (the forward baseline and Fast Downward keep their own ways)
TASK_PLANNERS: dict[str, Callable[[Path, RecoveryRules], TaskPlanner]] = {
    "regression": _regression,
    # the same networks; a subgoal is taken only if what it serves stays reachable (f_reach)
    # and the picks other goal literals still need stay likely
    "regression-ahead": _regression_ahead,
    # the same planner; the agent tries each action in its model first and refuses those
    # that do not plan (`agents/hierarchical.py`)
    "regression-ahead-checked": _regression_ahead,
    # the same, and when every action offered fails its check, a neighbour in the way is moved
    # aside first (`agents/clearing.py`)
    "regression-ahead-clearing": _regression_ahead,
    "regression-paper": _regression_paper,  # the paper's loop (`paper_loop.py`), no rules
    # our loop part by part, from the paper's (the task ladder): breadth first alone, then
    # goal literals that wait, then literals whose preimage holds taken (`planner.Loop`);
    # `regression` also follows its chain
    "regression-bfs": _regression_parts(
        "regression-bfs", waits=False, holds=False, keeps_chain=False
    ),
    "regression-bfs-wait": _regression_parts("regression-bfs-wait", holds=False, keeps_chain=False),
    "regression-bfs-wait-holds": _regression_parts("regression-bfs-wait-holds", keeps_chain=False),
    "forward": _forward,
    "fd": _fast_downward,
}


def _sampler(checkpoints: Path, rules: RecoveryRules) -> MotionGenerator:
    from hsgplan.motion.sampler import GeometricSampler

    return GeometricSampler()


def _learned(
    model: str, place_for_push: bool = False, checked: bool = False
) -> Callable[[Path, RecoveryRules], MotionGenerator]:
    def make(checkpoints: Path, rules: RecoveryRules) -> MotionGenerator:
        from hsgplan.domain.parameters import MotionPrimitive
        from hsgplan.motion.generator import LearnedMotion
        from hsgplan.motion.interface import DRY_RUNS

        folders = {kind: checkpoints / f"{kind.value}-{model}" for kind in MotionPrimitive}
        return LearnedMotion(model, folders, rules, place_for_push, DRY_RUNS if checked else 0)

    make.model = model  # the networks it reads: `LEARNED_MOTION`
    return make


def _random(checkpoints: Path, rules: RecoveryRules) -> MotionGenerator:
    from hsgplan.motion.generator import RandomMotion

    return RandomMotion(rules=rules)


# name -> factory of a motion generator from the folder of motion checkpoints and the recovery
# rules in force (the geometric sampler, the oracle's, keeps its own)
MOTION_GENERATORS: dict[str, Callable[[Path, RecoveryRules], MotionGenerator]] = {
    "sampler": _sampler,
    "gnn": _learned("gnn"),
    # the same GNNs, each proposal planned before it is made (the sampler's budget of dry runs)
    "gnn-checked": _learned("gnn", checked=True),
    # ... and a place before a push asks the push network where to put the object (alone, the
    # look ahead to the push showed no gain on the tune split: docs/decisions.md, `gnn-next`)
    "gnn-next-checked": _learned("gnn", place_for_push=True, checked=True),
    "mlp": _learned("mlp"),
    "random": _random,
}

# name -> (task planner, motion generator)
AGENTS: dict[str, tuple[str, str]] = {
    "oracle": ("fd", "sampler"),  # the rules and geometry: the ceiling the learned agents meet
    "regression": ("regression", "sampler"),  # the learned task level alone
    "learned": ("regression", "gnn"),  # the paper's system as we build it: both levels learned
}

# agents that are not a task planner beside a motion generator: name -> what it is
WHOLE_AGENTS: dict[str, str] = {
    "search": "Fast Downward's plan refined by sampling and simulating, backtracking",
    "stream": "PDDLStream's incremental algorithm: Fast Downward over sampled poses and grasps",
    "stream-goal": "the same, its stack and place streams sampling where the goal leads",
    "stream-focused": "PDDLStream's focused algorithm: plan with optimistic stream outputs, "
    "then evaluate only the streams the plan uses",
    "stream-focused-goal": "the same with the goal-directed streams of stream-goal",
}
# task planners of the paper's agent or a rung of the ladder to ours: a table's column is named
# by its motion generator alone (and set beside the paper's)
PAPER_LIKE = (
    "regression",
    "regression-paper",
    "regression-bfs",
    "regression-bfs-wait",
    "regression-bfs-wait-holds",
)
# task planners whose agent checks each action in its model before taking it
CHECKED_PLANNERS = ("regression-ahead-checked", "regression-ahead-clearing")
# ... and whose agent also moves a neighbour aside when every action offered fails its check
CLEARING_PLANNERS = ("regression-ahead-clearing",)
STREAM_AGENTS = ("stream", "stream-goal", "stream-focused", "stream-focused-goal")
AGENT_NAMES = [*AGENTS, *WHOLE_AGENTS]
# The search-based baselines Table 2 may time against ours (`hsgplan bench timing --search`),
# and the one it times unless told.
SEARCH_BASELINES = ("search", *STREAM_AGENTS)
DEFAULT_SEARCH = "stream-goal"  # the strongest (docs/results.md, Table 2)


def _known(what: str, name: str, names) -> None:
    if name not in names:
        raise InvalidInputError(f"unknown {what} '{name}' (known: {', '.join(names)})")


def make_planner(
    name: str, checkpoint: Path = TASK_CHECKPOINT, rules: RecoveryRules = ALL_RULES
) -> TaskPlanner:
    _known("task planner", name, TASK_PLANNERS)
    return TASK_PLANNERS[name](checkpoint, rules)


def make_motion(
    name: str, checkpoints: Path = MOTION_CHECKPOINTS, rules: RecoveryRules = ALL_RULES
) -> MotionGenerator:
    _known("motion generator", name, MOTION_GENERATORS)
    return MOTION_GENERATORS[name](checkpoints, rules)


def agent_name(agent: str, planner: str | None = None, motion: str | None = None) -> str:
    """The agent a command asks for: a registered one, with its planner or its motion
    generator replaced where `planner` or `motion` is given."""
    if agent in WHOLE_AGENTS:
        if planner or motion:
            raise InvalidInputError(
                f"the agent '{agent}' has no task planner or motion generator to replace"
            )
        return agent
    if planner is None and motion is None:
        agent_parts(agent)
        return agent
    default_planner, default_motion = agent_parts(agent)
    return f"{planner or default_planner}+{motion or default_motion}"


def agent_parts(name: str) -> tuple[str, str]:
    """(task planner, motion generator) of a registered agent or of `PLANNER+MOTION`."""
    if "+" in name:
        planner, _, motion = name.partition("+")
        _known("task planner", planner, TASK_PLANNERS)
        _known("motion generator", motion, MOTION_GENERATORS)
        return planner, motion
    _known("agent", name, AGENT_NAMES + ["PLANNER+MOTION"])
    if name in WHOLE_AGENTS:
        raise InvalidInputError(f"the agent '{name}' is not a task planner and a motion generator")
    return AGENTS[name]


LEARNED_PLANNERS = (
    "regression",
    "regression-ahead",
    "regression-ahead-checked",
    "regression-ahead-clearing",
    "regression-paper",
    "forward",
)
# learned motion generator -> the model whose networks it reads (`KIND-MODEL` folders)
LEARNED_MOTION = {
    name: make.model for name, make in MOTION_GENERATORS.items() if hasattr(make, "model")
}


def agent_checkpoints(
    name: str, checkpoint: Path = TASK_CHECKPOINT, motion_checkpoints: Path = MOTION_CHECKPOINTS
) -> list[Path]:
    """The checkpoint folders an agent reads (what a run of it is fingerprinted by)."""
    if name in WHOLE_AGENTS:
        return []
    planner, motion = agent_parts(name)
    folders = [checkpoint] if planner in LEARNED_PLANNERS else []
    if motion in LEARNED_MOTION:
        from hsgplan.domain.parameters import MotionPrimitive

        model = LEARNED_MOTION[motion]
        folders += [motion_checkpoints / f"{kind.value}-{model}" for kind in MotionPrimitive]
    return folders


def default_checkpoints(
    name: str,
    worlds: list[World],
    checkpoint: Path | None = None,
    motion_checkpoints: Path | None = None,
) -> tuple[Path, Path, str | None]:
    """The task and motion folders an agent runs with where a command names none: the shipped
    networks, which know the kitchen's names, unless a world names others, where the shipped
    networks that read kind and size take their place (where they hold the agent's parts and
    no folder named by hand reads names). Returns the two folders and a line saying what was
    swapped, or None (and the folders as they were)."""
    from hsgplan.paths import MOTION_GEOMETRY_CHECKPOINTS, TASK_GEOMETRY_CHECKPOINT, shipped
    from hsgplan.scene_graph.names import unnamed

    task = checkpoint or TASK_CHECKPOINT
    motion = motion_checkpoints or MOTION_CHECKPOINTS
    others = sorted({n for w in worlds for n in unnamed(w)})
    if not others:
        return task, motion, None
    # only the folders of the agent's learned parts are swapped (a run records what it read)
    planner, generator = agent_parts(name) if name not in WHOLE_AGENTS else ("", "")
    geometry = (
        task if checkpoint or planner not in LEARNED_PLANNERS else TASK_GEOMETRY_CHECKPOINT,
        motion if motion_checkpoints or generator not in LEARNED_MOTION
        else MOTION_GEOMETRY_CHECKPOINTS,
    )  # fmt: skip
    before, after = agent_checkpoints(name, task, motion), agent_checkpoints(name, *geometry)
    if before == after or not all(shipped(f).exists() for f in after):
        return task, motion, None
    if any(_reads_names(shipped(f)) for f in after):  # a folder named by hand binds it to names
        return task, motion, None
    said = (
        f"a scene here names what the shipped networks do not know by name ({', '.join(others)}): "
        "running the networks that read kind and size "
        f"({', '.join(str(f) for f in geometry if f not in (task, motion))})"
    )
    return *geometry, said


def _reads_names(folder: Path) -> bool:
    """Whether a checkpoint folder's networks know nodes by name (`features` "names", what a
    configuration saved before the setting existed means); a folder of trainings (`seed-S`) by
    its first; a folder that cannot be read is left to the loader to refuse."""
    import json

    config = folder / "preimage" / "config.json"
    config = config if config.exists() else folder / "config.json"
    trainings = sorted(folder.glob("seed-*")) if not config.exists() else []
    if trainings:
        return _reads_names(trainings[0])
    try:
        return json.loads(config.read_text()).get("features", "names") == "names"
    except (OSError, ValueError, AttributeError):
        return False


def check_reads(folders: list[Path], world: World, scene: str | Path | None) -> None:
    """Refuse, in one line, checkpoints whose networks know the kitchen's names in a scene
    that names others (networks of the "geometry" features read any scene)."""
    from hsgplan.scene_graph.names import unnamed

    others = unnamed(world)
    bound = [f for f in folders if _reads_names(f)] if others else []
    if bound:
        raise InvalidInputError(
            f"the networks of '{bound[0]}' know the kitchen's objects, shelves and regions by "
            f"name; scene '{scene}' names others ({', '.join(others)}): networks that read kind "
            "and size are checkpoints/task-geometry and checkpoints/motion-geometry (GNNs only)"
        )


def make_agent(
    name: str,
    checkpoint: Path = TASK_CHECKPOINT,
    motion_checkpoints: Path = MOTION_CHECKPOINTS,
    rules: RecoveryRules = ALL_RULES,
) -> Agent:
    """An agent by name, its learned parts from these checkpoint folders, under the recovery
    rules `rules` (`hsgplan.domain.recovery`; the search baselines have none); an unknown name
    or a missing checkpoint is refused in one line."""
    from hsgplan.agents.hierarchical import HierarchicalAgent

    if name == "search":
        from hsgplan.agents.search import SearchAgent

        return SearchAgent()
    if name in STREAM_AGENTS:
        from hsgplan.agents.stream import make_stream_agent

        return make_stream_agent(name)

    planner, motion = agent_parts(name)
    return HierarchicalAgent(
        name,
        make_planner(planner, checkpoint, rules),
        make_motion(motion, motion_checkpoints, rules),
        rules,
        check_actions=planner in CHECKED_PLANNERS,
        clear_way=planner in CLEARING_PLANNERS,
    )
