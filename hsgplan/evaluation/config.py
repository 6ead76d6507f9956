"""What an evaluation runs, as a configuration: its agent, goals, protocol and what the agent
sees with. Kept apart from running it (`evaluation.protocol`), and light to import: the command
line takes its options' defaults from here."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field, replace
from functools import lru_cache
from pathlib import Path

from hsgplan.domain.checks import BOUNDS, bounded, check_fields, read_text, setting
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.recovery import (
    NO_FAILURE_RULES,
    PAPER,
    PROTOCOLS,
    RecoveryRules,
)
from hsgplan.domain.scene import World
from hsgplan.domain.scene_file import MAX_SCENE_BYTES, default_world, read_world_text, read_worlds

# What an agent sees the simulated world with (`evaluation.observers` makes them): gt, the
# simulator's poses; rgb, f_p on the fixed cameras' images; rgb-latest, f_p with each look's
# estimate taken as it comes (`perception.observer`'s `steady` rule off, to measure it);
# rgb-keypoint-yaw, f_p with each box's yaw as its keypoints say (`perception.silhouette` off).
OBSERVERS = ("gt", "rgb", "rgb-latest", "rgb-keypoint-yaw")


def check_observer(name: str) -> None:
    if name not in OBSERVERS:
        raise InvalidInputError(f"--perception '{name}': one of {', '.join(OBSERVERS)}")


def check_seen(
    perception: str,
    worlds: Iterable[World],
    scene: str | Path | None,
    checkpoint: str | Path | None = None,
) -> None:
    """Refuse f_p (`checkpoint`'s, else the shipped one) a scene it cannot see, in one line
    (`unseeable`)."""
    if perception != "gt" and (why := unseeable(worlds, scene, checkpoint)):
        raise InvalidInputError(f"--perception {perception}: {why}; see it with --perception gt")


def unseeable(
    worlds: Iterable[World], scene: str | Path | None, checkpoint: str | Path | None = None
) -> str | None:
    """Why f_p (`checkpoint`'s, else the shipped one) cannot see the scenes of `worlds` (read
    from `scene`), or None: one has objects whose look it has not learned, or other cameras
    (`perception.vocabulary`)."""
    from hsgplan.paths import perception_folder, shipped
    from hsgplan.perception.vocabulary import read_vocabulary

    vocabulary = read_vocabulary(shipped(perception_folder(checkpoint)))
    why = next(filter(None, map(vocabulary.unseen_looks, worlds)), None)
    return None if why is None else f"f_p cannot see scene '{scene}': {why}"


# the tables of an `eval world` run (`table1.tables`), in their order
TABLES = ("success", "failures", "time")


@dataclass(frozen=True)
class EvalConfig:
    agent: str
    sizes: tuple[int, ...]
    goals: int = field(metadata=bounded(**BOUNDS["goals"]))  # per size (a goal file: unused)
    seed: int = field(metadata=bounded(**BOUNDS["seed"]))
    goals_file: str | None = None
    repeats: int = setting(1, **BOUNDS["repeats"])
    checkpoint: str | None = None  # the task planner's folder (None: the shipped one)
    motion_checkpoints: str | None = None  # the folder of motion networks (None: shipped)
    perception: str = "gt"  # what the agent sees: one of OBSERVERS
    perception_checkpoint: str | None = None  # f_p's network (None: the shipped one)
    # PROTOCOLS: what a failed primitive does to the episode (the paper's: every headline's)
    protocol: str = PAPER
    # rules switched off (any under the recovering protocol, the perception rules under both)
    rules_off: tuple[str, ...] = ()
    # f_p's and its tracker's rules set otherwise than shipped, NAME=VALUE (`perception.rules`)
    perception_rules: tuple[str, ...] = ()
    # the motion planner's rules set otherwise than shipped, NAME=VALUE (`sim.plan_rules`)
    plan_rules: tuple[str, ...] = ()
    scene: str | None = None  # a scene file or a folder of them (None: the kitchen)
    # the split its goals and start scenes are drawn from (`evaluation.splits`; None: a bare
    # seed, exploration, its goals drawn from the whole goal space)
    split: str | None = None

    def __post_init__(self) -> None:
        check_fields(self)
        if self.split is not None:
            from hsgplan.evaluation.splits import check_seed, split_named

            if self.goals_file:
                raise InvalidInputError("--split draws its goals: give no --goals-file with it")
            check_seed(split_named(self.split), self.seed)
        check_observer(self.perception)
        if self.protocol not in PROTOCOLS:
            raise InvalidInputError(f"protocol '{self.protocol}': one of {', '.join(PROTOCOLS)}")
        object.__setattr__(self, "rules_off", tuple(self.rules_off))
        RecoveryRules().without(self.rules_off)  # an unknown rule's name is refused here
        object.__setattr__(self, "perception_rules", tuple(self.perception_rules))
        if self.perception_rules:
            from hsgplan.perception.rules import PerceptionRules

            PerceptionRules.parse(self.perception_rules)  # a bad setting refused here
        object.__setattr__(self, "plan_rules", tuple(self.plan_rules))
        if self.plan_rules:
            from hsgplan.sim.plan_rules import PlanRules

            PlanRules.parse(self.plan_rules)
        if self.protocol == PAPER and (kept := set(self.rules_off) - set(NO_FAILURE_RULES)):
            raise InvalidInputError(
                f"the paper protocol has no recovery rule to switch off ({', '.join(sorted(kept))}"
                f"); only those that recover from no failure: {', '.join(NO_FAILURE_RULES)}"
            )
        # a bad scene, too
        check_seen(self.perception, self.worlds().values(), self.scene, self.perception_checkpoint)

    def worlds(self) -> dict[str | None, World]:
        """The worlds its episodes run in, by scene file ({None: the kitchen} without one)."""
        if self.scene is None:
            return {None: default_world()}
        return {str(p): world_of_file(str(p)) for p in read_worlds(self.scene)}

    def rules(self) -> RecoveryRules:
        """The rules its agent runs under: under the paper's protocol no recovery rule but
        those that recover from no failure (the perception rules: the robot looks again where
        it is unsure of what it acts on or judges, and judges a step on what it came near; the
        checking agents' `CHECKING_RULES`), unless switched off."""
        rules = RecoveryRules().without(self.rules_off)
        if self.protocol == PAPER:
            kept = {r: getattr(rules, r) for r in NO_FAILURE_RULES}
            return replace(RecoveryRules.none(), **kept)
        return rules


def world_of_file(path: str) -> World:
    """A scene file's world, parsed once per process and content (every episode of a run asks
    for it; a file written again is read again)."""
    return _world_of_text(path, read_text(Path(path), "scene file", MAX_SCENE_BYTES))


@lru_cache(maxsize=64)
def _world_of_text(path: str, text: str) -> World:
    return read_world_text(text, path)
