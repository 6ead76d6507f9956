"""The evaluation protocol: which episodes an `eval` runs, and running them.

Goals come from the seeded generator (`goals` per size; the paper leaves stacking out of
2-object goals, since its demonstrations cover them) or from a goal file; every goal is run
`repeats` times (the paper runs each five times), each from its own start scene. Each
episode's seed is derived from the run's seed, the size, the goal's index and the repeat, so
any episode can be rerun alone. Finished episodes are appended to `episodes.jsonl` in the run
folder as they finish: an interrupted run, started again with the same command, skips what is
done. What the episodes sum to is `evaluation/summary.py`.

Two protocols. `paper`, the paper's: the agent decides once per step from the scene it sees,
with no recovery rule but the perception rules (`hsgplan.domain.recovery`, `PERCEPTION_RULES`:
they recover from no failure; `rules_off` may switch them off), and the first primitive that
fails (refused while planning, or failed in execution) ends the episode as an execution
failure; the step limit ends it as overstep. `recovering`, ours: a failed primitive costs its
step and the loop goes on from what it observes, under the recovery rules (all of them, or all
but `rules_off`).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, fields, replace
from functools import lru_cache, partial
from pathlib import Path

from hsgplan.domain.checks import (
    read_json,
)
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.goals import Goal, parse_goal, read_goal_file
from hsgplan.domain.recovery import PAPER, RECOVERING
from hsgplan.domain.scene import World
from hsgplan.domain.scene_file import default_world
from hsgplan.evaluation.config import EvalConfig, world_of_file
from hsgplan.evaluation.episode import EpisodeRecord
from hsgplan.evaluation.observers import make_observer
from hsgplan.evaluation.seeds import episode_seed
from hsgplan.evaluation.splits import split_goals, split_named
from hsgplan.paths import perception_folder
from hsgplan.runner.items import run_items
from hsgplan.runner.run_folder import CONFIG, add_wall_seconds, check_claim


@dataclass(frozen=True)
class EpisodeSpec:
    size: int
    index: int
    goal: str
    seed: int
    repeat: int = 0
    scene: str | None = None  # the scene file it runs in (None: the kitchen)

    @property
    def key(self) -> str:
        where = f"{Path(self.scene).stem}/" if self.scene else ""
        return f"{where}{self.size}/{self.index}/{self.seed}/{self.goal}"


def check_world(config: EvalConfig) -> None:
    """Refuse, in one line, an agent whose networks know nodes by name in a scene whose names
    they were not trained on, and a goal of the goals file that the agent is not for
    (`agents.goal_scope`: random goals always are)."""
    from hsgplan.agents.goal_scope import check_goal

    for scene, world in config.worlds().items():
        check_agent_world(config.agent, world, scene, *checkpoints(config))
        if config.goals_file:
            for goal in read_goal_file(Path(config.goals_file), world):
                if goal.size in config.sizes:
                    check_goal(config.agent, goal)


def check_agent_world(
    agent: str,
    world: World,
    scene: str | Path | None,
    checkpoint: Path | None = None,
    motion_checkpoints: Path | None = None,
) -> None:
    """`registry.check_reads` on the checkpoint folders of an agent (default: the shipped)."""
    from hsgplan.agents.registry import agent_checkpoints, check_reads
    from hsgplan.paths import MOTION_CHECKPOINTS, TASK_CHECKPOINT

    folders = agent_checkpoints(
        agent, checkpoint or TASK_CHECKPOINT, motion_checkpoints or MOTION_CHECKPOINTS
    )
    check_reads(folders, world, scene)


def episode_specs(config: EvalConfig) -> list[EpisodeSpec]:
    """Every episode of a run: in each of its worlds, the same goal seeds."""
    return [s for scene, world in config.worlds().items() for s in _specs(config, scene, world)]


def _specs(config: EvalConfig, scene: str | None, world: World) -> list[EpisodeSpec]:
    by_size: dict[int, list[Goal]] = {}
    if config.goals_file:
        for g in read_goal_file(Path(config.goals_file), world):
            by_size.setdefault(g.size, []).append(g)
        by_size = {n: gs for n, gs in by_size.items() if n in config.sizes}
        if not by_size:
            raise InvalidInputError(f"'{config.goals_file}' holds no goal of the sizes asked for")
    else:
        split = split_named(config.split) if config.split else None
        for n in config.sizes:
            by_size[n] = split_goals(
                split, n, config.goals, config.seed, stacking=n > 2, world=world
            )
    return [
        EpisodeSpec(n, i, str(g), episode_seed(config.seed, n, i, r), r, scene)
        for n in sorted(by_size)
        for i, g in enumerate(by_size[n])
        for r in range(config.repeats)
    ]


@lru_cache(maxsize=2)
def _worker_agent(config: EvalConfig):
    """One agent per worker process and configuration: `reset` starts every episode afresh,
    and loading the networks once saves a third of a second an episode."""
    from hsgplan.agents.registry import make_agent

    return make_agent(config.agent, *checkpoints(config), config.rules())


@lru_cache(maxsize=2)
def _worker_observer(config: EvalConfig):
    return make_observer(config.perception, config.perception_checkpoint, config.perception_rules)


EVAL_KIND = "eval"


def run_config(config: EvalConfig) -> dict:
    """What an evaluation's run folder is claimed with: its settings and a fingerprint of the
    checkpoints its agent reads and of its goal file, so that a resumed run never mixes
    episodes of one checkpoint with another's."""
    from hsgplan.agents.registry import agent_checkpoints
    from hsgplan.checkpoint import fingerprint

    folders = agent_checkpoints(config.agent, *checkpoints(config))
    settings = asdict(config)
    if config.perception == "gt":  # as runs were claimed before f_p could see
        del settings["perception"], settings["perception_checkpoint"]
    else:
        folders = [*folders, perception_folder(config.perception_checkpoint)]
    if config.protocol == RECOVERING and not config.rules_off:  # as before protocols were named
        del settings["protocol"], settings["rules_off"]
    else:
        settings["rules_off"] = list(config.rules_off)
    if config.scene is None:  # as runs were claimed before scenes were files
        del settings["scene"]
    for rules in ("perception_rules", "plan_rules"):  # as runs were claimed before rules were set
        if not getattr(config, rules):
            del settings[rules]
        else:
            settings[rules] = list(getattr(config, rules))
    if config.split is None:  # as runs were claimed before splits
        del settings["split"]
    files = [Path(p) for p in (config.goals_file, *config.worlds()) if p]
    return settings | {
        "sizes": list(config.sizes),
        "fingerprint": fingerprint([*folders, *files]),
    }


def read_eval_config(run_dir: Path) -> EvalConfig:
    """The configuration an evaluation's run folder was claimed with; one line if damaged."""
    saved = read_json(run_dir / CONFIG, "run configuration")
    names = {f.name for f in fields(EvalConfig)}
    try:
        config = EvalConfig(**{k: v for k, v in saved.items() if k in names})
        return replace(
            config,
            sizes=tuple(config.sizes),
            rules_off=tuple(config.rules_off),
            perception_rules=tuple(config.perception_rules),
            plan_rules=tuple(config.plan_rules),
        )
    except TypeError:
        raise InvalidInputError(
            f"'{run_dir / CONFIG}' is not an evaluation's configuration"
        ) from None


def check_runs(config: EvalConfig, out: Path, agents: dict[str, tuple[str, str]]) -> None:
    """Refuse, before anything is written, a folder `out/NAME` (one per agent and perception;
    `out/NAME/seed-S` per training) that is no evaluation's or holds episodes of another
    configuration, checkpoint or goal file."""
    for name, (agent, perception) in agents.items():
        method = replace(config, agent=agent, perception=perception)
        for seed, trained_config in trained(method).items():
            run_dir = training_dir(out / name, seed)
            refusal = (
                f"'{run_dir}' holds episodes of another configuration, checkpoint or goal file; "
                "use another --out"
            )
            check_claim(run_dir, EVAL_KIND, run_config(trained_config), refusal)


def trained(config: EvalConfig) -> dict[int | None, EvalConfig]:
    """The configuration of each training an evaluation runs, by training seed: one for each
    `seed-S` of a trainings folder named by `checkpoint` or `motion_checkpoints`
    (`hsgplan.trainings`); {None: config} where neither is one."""
    from hsgplan.trainings import paired

    return {
        seed: replace(config, checkpoint=task, motion_checkpoints=motion)
        for seed, (task, motion) in paired(config.checkpoint, config.motion_checkpoints).items()
    }


def training_dir(run_dir: Path, seed: int | None) -> Path:
    """Where one training's episodes are logged: the method's folder, or its `seed-S`."""
    return run_dir if seed is None else run_dir / f"seed-{seed}"


def checkpoints(config: EvalConfig) -> tuple[Path, Path]:
    """The task planner's and the motion networks' folders an evaluation runs with."""
    from hsgplan.paths import MOTION_CHECKPOINTS, TASK_CHECKPOINT

    return (
        Path(config.checkpoint or TASK_CHECKPOINT),
        Path(config.motion_checkpoints or MOTION_CHECKPOINTS),
    )


def run_spec(config: EvalConfig, spec: EpisodeSpec) -> dict:
    """One episode in this process (a worker): its record as JSON."""
    from hsgplan.evaluation.episode import run_episode
    from hsgplan.sim.env import KitchenStorageEnv

    agent = _worker_agent(config)
    world = world_of_file(spec.scene) if spec.scene else default_world()
    from hsgplan.sim.plan_rules import PlanRules

    env = KitchenStorageEnv(
        observer=_worker_observer(config),
        rules=config.rules(),
        visuals=False,
        plan_rules=PlanRules.parse(config.plan_rules),
        world=world,
    )
    goal = parse_goal(spec.goal, world=world)
    record = run_episode(env, agent, goal, spec.seed, end_at_failure=config.protocol == PAPER)
    return replace(record, repeat=spec.repeat, scene=spec.scene).to_json()


def run_evaluation(
    config: EvalConfig,
    run_dir: Path | None,
    workers: int = 2,
    on_episode: Callable[[EpisodeRecord], None] | None = None,
    ray: str | None = None,
) -> list[EpisodeRecord]:
    """Run every episode not yet in `run_dir`, `workers` at a time; all records, in order.
    The wall-clock seconds spent running episodes are added to the run folder's timing."""
    check_world(config)
    specs = episode_specs(config)
    start = time.perf_counter()
    try:
        rows = run_items(
            partial(run_spec, config),
            specs,
            key=lambda s: s.key,
            run_dir=run_dir,
            kind=EVAL_KIND,
            config=run_config(config),
            workers=workers,
            ray=ray,
            on_result=on_episode and (lambda row: on_episode(EpisodeRecord.from_json(row))),
        )
    finally:
        if run_dir is not None and (run_dir / CONFIG).is_file():
            add_wall_seconds(run_dir, time.perf_counter() - start, workers)
    return [EpisodeRecord.from_json(row) for row in rows]
