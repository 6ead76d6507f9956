"""What an episode of `KitchenStorageEnv` is given (`ResetOptions`) and what each of its steps
gives the agent (`Observation`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hsgplan.domain.goals import Goal, parse_goal
from hsgplan.domain.scene import World
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.symbol_mapping import SymbolMapping
from hsgplan.symbolic.generator import random_goals


@dataclass(frozen=True)
class Observation:
    """What the agent gets (`scene_graph`, `symbols`: the observer's), and the truth.

    Attributes:
        true_symbols: f_m of the simulator's poses; the same object as `symbols` when the
            observer is the ground truth.
        unseen: objects the observer did not see this time (their poses carried over).
    """

    scene_graph: GeometricSceneGraph
    symbols: SymbolMapping
    rgb: np.ndarray | None
    true_symbols: SymbolMapping
    unseen: tuple[str, ...] = ()
    unknown: tuple[str, ...] = ()
    uncertain: tuple[str, ...] = ()


@dataclass(frozen=True)
class ResetOptions:
    """What an episode is about: the goal, and the scene's objects: the goal's, and `others`
    (objects no goal literal names, placed by the same sampler: the full scene a demonstration
    may be recorded in)."""

    goal: Goal
    p_elsewhere: float = 0.3
    others: tuple[str, ...] = ()

    def objects(self) -> tuple[str, ...]:
        return self.goal.world.sort_objects({*self.goal.objects, *self.others})


def reset_options(
    options: ResetOptions | dict | None, objects: int, seed: int, world: World
) -> ResetOptions:
    """The options `reset` was given, as `ResetOptions` (a random goal of `objects` objects
    drawn from `seed` where none is named)."""
    if isinstance(options, ResetOptions):
        return options
    options = options or {}
    goal = options.get("goal")
    if goal is None:
        goal = random_goals(objects, 1, seed, world=world)[0]
    if isinstance(goal, str):
        goal = parse_goal(goal, world=world)
    if not isinstance(goal, Goal):
        raise ValueError("options['goal']: a Goal or goal text")
    return ResetOptions(goal, float(options.get("p_elsewhere", ResetOptions.p_elsewhere)))
