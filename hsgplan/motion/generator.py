"""Motion generators behind one interface: parameters for the action the task level chose.

`LearnedMotion` scores every bin pair with a trained network on the grounded scene graph (the
GNN or the MLP baseline); `RandomMotion` is the paper's single-shot random baseline, uniform
over the bins; `motion/sampler.py` holds the geometric sampler, the oracle's generator. A pick
has no parameters, and a stack takes its position from the object below, so only a place onto
a surface and a push are chosen over bins.

`propose` is what an agent calls, once per step: the first of `ranked` that has not failed for
good earlier in the episode (a generator that would propose the same failed bins in an
unchanged scene takes its next-ranked proposal instead). The learned generators are single
shot as in the paper: they ignore the dry run an agent may offer.
"""

from __future__ import annotations

import random
from collections.abc import Callable
from pathlib import Path
from typing import Protocol

import torch
from torch_geometric.data import Batch

from hsgplan.domain.actions import Action, Pick, Place, intended_literal
from hsgplan.domain.parameters import (
    BINS,
    MotionPrimitive,
    PickParams,
    PlaceParams,
    PrimitiveParams,
    PushParams,
    params_for,
)
from hsgplan.domain.predicates import Literal, Predicate
from hsgplan.domain.world import SURFACES
from hsgplan.motion.models import load_motion_net
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.grounding import check_subgoal, ground
from hsgplan.sim.outcome import Outcome, Status

Feasibility = Callable[[PrimitiveParams], bool]
# Failures that say these parameters will not work here; anything else may be tried again.
DO_NOT_RETRY = frozenset({Status.NO_IK, Status.NO_PATH, Status.EFFECT_NOT_REACHED, Status.INVALID})


def primitive_of(subgoal: Literal) -> MotionPrimitive:
    return MotionPrimitive.PLACE if subgoal.predicate is Predicate.ON else MotionPrimitive.PUSH


class MotionGenerator(Protocol):
    name: str

    def reset(self, seed: int) -> None:
        """A new episode: nothing has failed yet."""

    def propose(
        self,
        sg: GeometricSceneGraph,
        action: Action,
        following: Action | None = None,
        feasible: Feasibility | None = None,
    ) -> PrimitiveParams | None:
        """Parameters for `action` in the scene `sg` (None when every choice has failed).

        `following` is the action the task planner expects next, where it knows one;
        `feasible`, when given, dry-runs a candidate (plans it without executing it)."""

    def observe(self, params: PrimitiveParams, outcome: Outcome) -> None:
        """What executing the proposal came to."""


class SingleShotMemory:
    """What every generator remembers within an episode: the parameters that failed for good."""

    def __init__(self) -> None:
        self.failed: set[PrimitiveParams] = set()

    def reset(self, seed: int) -> None:
        self.failed = set()

    def observe(self, params: PrimitiveParams, outcome: Outcome) -> None:
        if outcome.status in DO_NOT_RETRY:
            self.failed.add(params)


class _BinGenerator(SingleShotMemory):
    """Picks and stacks need no choice; everything else is the first untried of `ranked`."""

    def ranked(self, sg: GeometricSceneGraph, subgoal: Literal) -> list[PlaceParams | PushParams]:
        raise NotImplementedError

    def propose(
        self,
        sg: GeometricSceneGraph,
        action: Action,
        following: Action | None = None,
        feasible: Feasibility | None = None,
    ) -> PrimitiveParams | None:
        if isinstance(action, Pick):
            return PickParams(action.obj)
        if isinstance(action, Place) and action.target not in SURFACES:
            return PlaceParams(action.obj, action.target)
        ranked = self.ranked(sg, intended_literal(action))
        return next((p for p in ranked if p not in self.failed), None)


def _all_params(kind: MotionPrimitive, subgoal: Literal, flat: list[int]):
    ny = BINS[kind][1]
    obj, target = subgoal.args
    return [params_for(kind, obj, target, (k // ny, k % ny)) for k in flat]


class LearnedMotion(_BinGenerator):
    """A trained motion network (GNN or MLP) per primitive, from checkpoint folders."""

    def __init__(self, name: str, folders: dict[MotionPrimitive, Path]) -> None:
        super().__init__()
        self.name = name
        self.nets = {kind: load_motion_net(folder) for kind, folder in folders.items()}

    def scores(self, sg: GeometricSceneGraph, subgoal: Literal) -> torch.Tensor:
        """Logits over the flattened bin pairs: [bins[0] * bins[1]]."""
        net = self.nets[primitive_of(subgoal)]
        with torch.inference_mode():
            return net(Batch.from_data_list([ground(sg, subgoal)]))[0]

    def ranked(self, sg: GeometricSceneGraph, subgoal: Literal) -> list[PlaceParams | PushParams]:
        order = torch.argsort(self.scores(sg, subgoal), descending=True, stable=True)
        return _all_params(primitive_of(subgoal), subgoal, order.tolist())


class RandomMotion(_BinGenerator):
    """Bins in a uniformly random order (seeded; `reset` reseeds it per episode)."""

    name = "random"

    def __init__(self, seed: int = 0) -> None:
        super().__init__()
        self.rng = random.Random(f"random-motion-{seed}")

    def reset(self, seed: int) -> None:
        super().reset(seed)
        self.rng = random.Random(f"random-motion-{seed}")

    def ranked(self, sg: GeometricSceneGraph, subgoal: Literal) -> list[PlaceParams | PushParams]:
        check_subgoal(subgoal, sg)
        kind = primitive_of(subgoal)
        flat = list(range(BINS[kind][0] * BINS[kind][1]))
        self.rng.shuffle(flat)
        return _all_params(kind, subgoal, flat)
