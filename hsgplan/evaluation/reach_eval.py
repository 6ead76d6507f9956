"""f_reach against the world: precision and recall on held-out executed primitives, by kind.

The questions are the labels `world_labels` draws from primitives executed in the simulated
world (`hsgplan collect reach`), collected with a seed no training run saw. Each is sorted into
the situation that decides it, named from the state with the world's limits (this is
evaluation; the planner never sees these rules): the hand already holds another object, the
target surface is full, the object (or the target object) has something on it, the shelf's
interior is full, the object to place is not in the hand, or none of these (ordinary).
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass
from enum import StrEnum
from pathlib import Path

import torch

from hsgplan.data.world_trials import WorldTrial, collection_worlds, load_world_trials
from hsgplan.domain.actions import Action, Place, Push
from hsgplan.domain.scene_file import default_world
from hsgplan.planning.regression.examples import world_labels
from hsgplan.planning.regression.planner import RegressionPlanner
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph


class QuestionKind(StrEnum):
    HAND_FULL = "hand full"
    SURFACE_FULL = "surface full"
    COVERED = "object covered"
    INTERIOR_FULL = "interior full"
    NOT_HELD = "object not in hand"
    ORDINARY = "ordinary"


def kind_of_question(state: SymbolicSceneGraph, action: Action) -> QuestionKind:
    held, world = state.held(), state.world
    if isinstance(action, Place):
        if held != action.obj:
            return QuestionKind.NOT_HELD
        t = action.target
        if t in world.surfaces:
            full = len(state.resting_on(t)) >= world.surface_capacity[t]
            return QuestionKind.SURFACE_FULL if full else QuestionKind.ORDINARY
        return QuestionKind.COVERED if state.resting_on(t) else QuestionKind.ORDINARY
    if held is not None and held != action.obj:
        return QuestionKind.HAND_FULL
    if state.resting_on(action.obj):
        return QuestionKind.COVERED
    if (
        isinstance(action, Push)
        and len(state.inside(action.shelf)) >= world.interior_capacity[action.shelf]
    ):
        return QuestionKind.INTERIOR_FULL
    return QuestionKind.ORDINARY


@dataclass(frozen=True)
class Scores:
    """Counts of one kind of question: true/false positives and negatives of "reachable"."""

    tp: int = 0
    fp: int = 0
    tn: int = 0
    fn: int = 0

    @property
    def questions(self) -> int:
        return self.tp + self.fp + self.tn + self.fn

    def as_json(self) -> dict:
        def ratio(a: int, b: int) -> float | None:
            return a / b if b else None

        return {
            "questions": self.questions,
            "reachable": self.tp + self.fn,
            "precision": ratio(self.tp, self.tp + self.fp),
            "recall": ratio(self.tp, self.tp + self.fn),
            "accuracy": ratio(self.tp + self.tn, self.questions),
            # of the questions the world says no to, how many the network says yes to
            "false_yes_rate": ratio(self.fp, self.fp + self.tn),
        }


def _add(s: Scores, truth: bool, said: bool) -> Scores:
    return Scores(
        s.tp + (truth and said),
        s.fp + (not truth and said),
        s.tn + (not truth and not said),
        s.fn + (truth and not said),
    )


@torch.inference_mode()
def evaluate_reach(checkpoint: Path, trials: list[WorldTrial] | Path) -> dict:
    """Scores by kind and overall: `{"by_kind": {kind: {...}}, "overall": {...}}`; a folder's
    trials are read in the worlds they were collected in (their names under "worlds" unless
    the kitchen alone), which the checkpoint must read (`check_reads`)."""
    names = None
    if isinstance(trials, Path):
        from hsgplan.agents.registry import check_reads

        worlds = collection_worlds(trials, default_world())
        names = None if worlds == [default_world()] else sorted({w.name for w in worlds})
        for world in worlds:
            check_reads([checkpoint], world, world.name)
        trials = load_world_trials(trials, worlds)
    planner = RegressionPlanner(checkpoint)
    scores: dict[str, Scores] = defaultdict(Scores)
    for trial in trials:
        labels = world_labels(trial)
        if not labels:
            continue
        lits = sorted(labels)
        kind = kind_of_question(trial.state, trial.action)
        for lit, said in zip(lits, planner.reachable(trial.state, lits), strict=True):
            scores[kind] = _add(scores[kind], labels[lit], said)
            scores["all"] = _add(scores["all"], labels[lit], said)
    overall = scores.pop("all", Scores())
    order = list(QuestionKind)
    return {
        "by_kind": {str(k): scores[k].as_json() for k in order if k in scores},
        "overall": overall.as_json(),
        "trials": len(trials),
        "worlds": names,
    }
