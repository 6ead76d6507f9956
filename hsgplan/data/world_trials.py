"""Primitives executed in the simulated world from staged symbolic states: f_reach's labels.

Made by `hsgplan collect reach` (`evaluation/record_reach.py`). A collection is a run folder
whose `episodes.jsonl` holds one line per chunk of consecutive staged states,
`{"key": "SEED/CHUNK", "result": {"states": [R, ...]}}`, with per state

    R = {"staged": false}                         the arrangement could not be staged
    R = {"staged": true, "objects": [names], "state": [literals],
         "trials": [{"action": "pick(x)", "status": S, "after": [literals] | null}, ...]}

`state` is what the world showed once staged (placement literals, `str(Literal)`); each trial
starts from it again: the action executed (`str(Action)`), the execution's status (a
`sim.outcome.Status` value, or `no_parameters` when no parameter choice could be planned and
nothing moved), and the symbolic state the world showed afterwards, null when something
toppled or fell (the scene then maps to no clean state).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from hsgplan.domain.actions import Action, parse_action
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.goals import parse_literal
from hsgplan.domain.predicates import Predicate
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph
from hsgplan.sim.outcome import Status

RESULTS = "episodes.jsonl"
NO_PARAMETERS = "no_parameters"


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
    return [str(lit) for lit in state.sorted_literals() if lit.predicate is not Predicate.CLEAR]


def _state(objects: list[str], literals: list[str]) -> SymbolicSceneGraph:
    return SymbolicSceneGraph.from_literals(objects, map(parse_literal, literals), limits=False)


def trials_of(result: dict) -> list[WorldTrial]:
    """The trials of one logged result (none for a state that was not staged)."""
    if not result.get("staged"):
        return []
    objects = result["objects"]
    state = _state(objects, result["state"])
    return [
        WorldTrial(
            state,
            parse_action(t["action"]),
            str(t["status"]),
            None if t["after"] is None else _state(objects, t["after"]),
        )
        for t in result["trials"]
    ]


def load_world_trials(folder: Path) -> list[WorldTrial]:
    """Every trial of a collection, in the order of the staged states' keys."""
    path = folder / RESULTS
    if not path.is_file():
        raise InvalidInputError(f"'{folder}' holds no collection of executed primitives")
    rows = {}
    try:
        for line in path.read_text(encoding="utf-8").splitlines():
            if not line.endswith("}"):
                continue  # a line cut short by an interruption: its state is redone
            row = json.loads(line)
            rows[str(row["key"])] = row["result"]
        return [
            t
            for k in sorted(rows, key=_key_order)
            for state in rows[k]["states"]
            for t in trials_of(state)
        ]
    except (ValueError, KeyError, TypeError, UnicodeDecodeError) as e:
        raise InvalidInputError(f"'{path}' is damaged: {e!r}") from e


def _key_order(key: str) -> tuple[int, ...]:
    return tuple(int(x) for x in key.split("/"))
