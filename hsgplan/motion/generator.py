"""Motion generators behind one interface: bins for a subgoal, best first.

`LearnedMotion` scores every bin pair with a trained network on the grounded scene graph (the
GNN or the MLP baseline); `RandomMotion` is the paper's single-shot random baseline, uniform
over the bins. Single-shot use takes the first of `ranked`.
"""

from __future__ import annotations

import random
from pathlib import Path
from typing import Protocol

import torch
from torch_geometric.data import Batch

from hsgplan.data.motion_tasks import MotionPrimitive
from hsgplan.data.motion_trials import BINS, params_for
from hsgplan.domain.parameters import PlaceParams, PushParams
from hsgplan.domain.predicates import Literal, Predicate
from hsgplan.motion.train import load_motion_net
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.grounding import check_subgoal, ground


def primitive_of(subgoal: Literal) -> MotionPrimitive:
    return MotionPrimitive.PLACE if subgoal.predicate is Predicate.ON else MotionPrimitive.PUSH


class MotionGenerator(Protocol):
    name: str

    def ranked(
        self, sg: GeometricSceneGraph, subgoal: Literal
    ) -> list[PlaceParams | PushParams]: ...


def _all_params(kind: MotionPrimitive, subgoal: Literal, flat: list[int]):
    ny = BINS[kind][1]
    obj, target = subgoal.args
    return [params_for(kind, obj, target, (k // ny, k % ny)) for k in flat]


class LearnedMotion:
    """A trained motion network (GNN or MLP) per primitive, from checkpoint folders."""

    def __init__(self, name: str, folders: dict[MotionPrimitive, Path]) -> None:
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


class RandomMotion:
    """Bins in a uniformly random order (seeded)."""

    name = "random"

    def __init__(self, seed: int = 0) -> None:
        self.rng = random.Random(f"random-motion-{seed}")

    def ranked(self, sg: GeometricSceneGraph, subgoal: Literal) -> list[PlaceParams | PushParams]:
        check_subgoal(subgoal, sg)
        kind = primitive_of(subgoal)
        flat = list(range(BINS[kind][0] * BINS[kind][1]))
        self.rng.shuffle(flat)
        return _all_params(kind, subgoal, flat)
