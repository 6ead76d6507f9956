"""Primitives executed in the simulated world from staged symbolic states: f_reach's labels.

Made by `hsgplan collect reach` (`collect/reach.py`) and `hsgplan collect visited`
(`collect/visited.py`). A collection is a run folder (`runner/items.py`): `config.json` and
`episodes.jsonl`, one line per staged state or episode, `{"key": "SEED/INDEX", "result": R}`
(`SEED/SIZE/INDEX` for an episode), with

    R = {"staged": false}                         the drawn state could not be staged
    R = {"states": [R, ...], ...}                 the states one episode of the agent visited
                                                  (`collect visited`), each as below
    R = {"objects": [names], "state": [literals],
         "trials": [{"action": "pick(x)", "status": S, "after": [literals] | null}, ...]}

`state` is the symbolic state the world showed once staged, as placement literals (On, In,
InGrasp; `str(Literal)`; Clear is derived). Every trial starts from that same state: the action
executed (`str(Action)`), the execution's status (a `sim.outcome.Status` value, or
`no_parameters` when the action had no parameter choice at all), and the symbolic state the
world showed afterwards (`map_symbols` of the scene), null when that mapping had anomalies
(something toppled, fell, or rests in no clean way). A trial whose parameter choices all failed
to plan moved nothing: its status is the last planning failure's and `after` is `state`.

States are read with the world's limits off (`limits=False`): `after` is an observation, and a
primitive may leave what no limit allows (a fifth object squeezed onto a shelf top).
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from hsgplan.domain.actions import Action, parse_action
from hsgplan.domain.checks import read_json, read_text
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.goals import parse_literal
from hsgplan.domain.predicates import Predicate
from hsgplan.domain.scene import World
from hsgplan.domain.scene_file import recorded_worlds
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.sim.outcome import Status

RESULTS = "episodes.jsonl"
NO_PARAMETERS = "no_parameters"
UNSTAGED: dict = {"staged": False}


@dataclass(frozen=True)
class WorldTrial:
    """One primitive executed from a staged state, and what the world showed after it."""

    state: SymbolicSceneGraph
    action: Action
    status: str
    after: SymbolicSceneGraph | None

    @property
    def succeeded(self) -> bool:
        """The primitive did what it was meant to and disturbed nothing (`sim.outcome`)."""
        return self.status == Status.SUCCESS and self.after is not None


def state_json(state: SymbolicSceneGraph) -> list[str]:
    """A state's placement literals, sorted (Clear follows from them)."""
    return [str(lit) for lit in state.sorted_literals() if lit.predicate is not Predicate.CLEAR]


def read_state(objects: Sequence[str], literals: Sequence[str], world: World) -> SymbolicSceneGraph:
    return SymbolicSceneGraph.from_literals(
        objects, (parse_literal(lit, world) for lit in literals), limits=False, world=world
    )


def state_row(state: SymbolicSceneGraph, trials: Sequence[WorldTrial]) -> dict:
    """The logged result of a staged state and the trials run from it."""
    if any(t.state != state for t in trials):
        raise ValueError("every trial of a row starts from the row's state")
    return {
        "objects": list(state.objects),
        "state": state_json(state),
        "trials": [
            {
                "action": str(t.action),
                "status": str(t.status),
                "after": None if t.after is None else state_json(t.after),
            }
            for t in trials
        ],
    }


def trials_of(row: dict, world: World) -> list[WorldTrial]:
    """The trials of one logged result in the world it was collected in; none for a state that
    was not staged."""
    if row.get("staged", True) is False:
        return []
    if "states" in row:
        return [t for r in row["states"] for t in trials_of(r, world)]
    objects = row["objects"]
    state = read_state(objects, row["state"], world)
    return [
        WorldTrial(
            state,
            parse_action(t["action"], world),
            str(t["status"]),
            None if t["after"] is None else read_state(objects, t["after"], world),
        )
        for t in row["trials"]
    ]


def collection_worlds(folder: Path, default: World) -> list[World]:
    """The worlds a collection was staged in, state k in the k-th: its configuration's scene
    file or folder of them (`collect reach --scene`), else `default` (a collection made without
    a scene records none)."""
    made = Path(folder) / "config.json"
    scene = read_json(made, "collection configuration").get("scene") if made.is_file() else None
    return recorded_worlds(scene, default, folder)


def load_world_trials(folder: Path, world: World | Sequence[World]) -> list[WorldTrial]:
    """Every trial of a collection folder collected in `world`, states in key order, trials in
    the order run. A collection staged round a folder of scenes gives their worlds in turn:
    state k was staged in the k-th (`collect reach --scene DIR`)."""
    worlds = [world] if isinstance(world, World) else list(world)
    path = Path(folder) / RESULTS
    if not path.is_file():
        raise InvalidInputError(f"'{folder}' holds no collection of executed primitives")
    made = read_json(Path(folder) / "config.json", "collection configuration")
    if made.get("kind") != "reach":
        raise InvalidInputError(f"'{folder}' is not a collection of executed primitives")
    lines = read_text(path, "collection").splitlines()
    results: dict[tuple[int, ...], dict] = {}
    for n, line in enumerate(lines, 1):
        try:
            row = json.loads(line)
        except json.JSONDecodeError:
            continue  # cut short by an interruption: the collector ran that state again
        try:
            results[_key_order(row["key"])] = row["result"]
        except (KeyError, TypeError, ValueError) as e:
            raise InvalidInputError(f"'{path}' line {n} is damaged: {_why(e)}") from None
    trials: list[WorldTrial] = []
    for key in sorted(results):
        result = results[key]
        try:
            trials += trials_of(result, worlds[key[-1] % len(worlds)])
        except (AttributeError, KeyError, TypeError, ValueError) as e:
            where = "/".join(map(str, key))
            raise InvalidInputError(f"'{path}' state {where} is damaged: {_why(e)}") from None
    return trials


def _key_order(key) -> tuple[int, ...]:
    if not isinstance(key, str):
        raise TypeError(f"key {key!r} is not a string")
    return tuple(int(x) for x in key.split("/"))


def _why(e: Exception) -> str:
    return f"missing {e}" if isinstance(e, KeyError) else " ".join(str(e).split())
