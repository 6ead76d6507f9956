"""Commands of the symbolic level: plan, goals."""

from __future__ import annotations

import json
from enum import StrEnum
from pathlib import Path
from typing import Annotated

import typer

from hsgplan.cli.common import (
    SceneOption,
    bounded_option,
    err,
    out,
    refuses_bad_input,
    scene_world,
    shown,
)
from hsgplan.cli.common import out_file as file_to_write
from hsgplan.domain.errors import InvalidInputError


class Search(StrEnum):
    auto = "auto"
    optimal = "optimal"
    fast = "fast"

    @property
    def optimal_flag(self) -> bool | None:
        return {"auto": None, "optimal": True, "fast": False}[self.value]


def _scene(goal_text: str, names_text: str | None, init: str | None, scene: Path | None = None):
    from hsgplan.domain.goals import parse_goal
    from hsgplan.scene_graph.symbolic import SymbolicSceneGraph

    world = scene_world(scene)
    goal = parse_goal(goal_text, world=world)
    names = list(goal.objects)
    if names_text is not None:
        given = [o.strip() for o in names_text.split(",") if o.strip()]
        if not given:
            raise InvalidInputError(f"--names '{names_text}' names no object")
        for o in given:
            world.kind_of(o)
        missing = [o for o in goal.objects if o not in given]
        if missing:
            raise InvalidInputError(f"--names lacks '{missing[0]}', which the goal names")
        names = list(world.sort_objects(given))
    if init:
        literals = parse_goal(init, validate=False, world=world).literals
        extra = {o for lit in literals for o in lit.objects(world)} - set(names)
        if extra:
            raise InvalidInputError(f"--init names '{sorted(extra)[0]}', which is not in the scene")
        state = SymbolicSceneGraph.from_literals(names, literals, world=world)
    else:
        state = SymbolicSceneGraph.initial(names, world=world)
    return goal, state


def _print_plan(plan, goal) -> None:
    out.print(f"[bold]goal[/] ({goal.size} objects): {goal}", highlight=False)
    for i, state in enumerate(plan.states):
        head = "start" if i == 0 else f"step {i}: [bold cyan]{plan.actions[i - 1]}[/]"
        out.print(f"\n{head}", highlight=False)
        out.print(state.to_text(), highlight=False, markup=False)
    out.print(
        f"\n{len(plan)} actions, planned by {plan.planner} in {plan.seconds:.2f} s; "
        f"goal holds: {goal.satisfied_by(plan.states[-1])}",
        highlight=False,
    )


@refuses_bad_input
def plan(
    goal: Annotated[
        str, typer.Option(help="Goal literals, e.g. 'On(butter, shelf_a) & In(cherries, shelf_a)'.")
    ],
    names: Annotated[
        str | None,
        typer.Option(help="Comma-separated objects in the scene (default: those the goal names)."),
    ] = None,
    init: Annotated[
        str | None,
        typer.Option(help="Start state as On/In/InGrasp literals (default: all on open_space)."),
    ] = None,
    search: Annotated[
        Search,
        typer.Option(
            help="optimal: shortest plan (A* with LM-cut, slow past 8 objects); "
            "fast: weighted A*; auto: optimal up to 6 objects."
        ),
    ] = Search.auto,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print the plan as JSON.", metavar="")
    ] = False,
    scene: SceneOption = None,
) -> None:
    """Plan a goal with Fast Downward and show the symbolic state after each step."""
    from hsgplan.planning.fast_downward import FastDownwardPlanner

    g, state = _scene(goal, names, init, scene)
    result = FastDownwardPlanner(optimal=search.optimal_flag).plan(state, g)
    if as_json:
        steps = [
            {
                "step": i,
                "action": None if i == 0 else str(result.actions[i - 1]),
                "state": [str(lit) for lit in s.sorted_literals()],
            }
            for i, s in enumerate(result.states)
        ]
        print(json.dumps(steps, indent=2))
    else:
        _print_plan(result, g)


@refuses_bad_input
def goals(
    objects: Annotated[int, typer.Option(help="Objects per goal (2-12).")],
    goals: Annotated[int, bounded_option("goals", "How many goals.")],
    seed: Annotated[
        int,
        bounded_option("seed", "Random seed; the same seed gives the same goals."),
    ] = 0,
    out_file: Annotated[
        Path | None,
        typer.Option("--out", help="Goal file to write (default: stdout).", parser=file_to_write),
    ] = None,
    stacking: Annotated[bool, typer.Option(help="Allow stacked goals.")] = True,
    scene: SceneOption = None,
) -> None:
    """Write random feasible goals, one per line (distribution: `symbolic/generator.py`)."""
    from hsgplan.domain.goals import write_goal_file
    from hsgplan.symbolic.generator import check_size, random_goals

    check_size(objects)
    drawn = random_goals(objects, goals, seed, stacking=stacking, world=scene_world(scene))
    header = f"hsgplan goals --objects {objects} --goals {goals} --seed {seed}" + (
        "" if stacking else " --no-stacking"
    )
    if scene is not None:
        header += f" --scene {scene}"
    if out_file is None:
        print(f"# {header}")
        for g in drawn:
            print(g)
        return
    write_goal_file(out_file, drawn, header=header)
    err.print(f"wrote {len(drawn)} goals to {shown(out_file)}")
