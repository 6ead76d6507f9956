"""Motion generators behind one interface: parameters for the action the task level chose.

`LearnedMotion` scores every bin pair with a trained network on the grounded scene graph (the
GNN or the MLP baseline); `RandomMotion` is the paper's single-shot random baseline, uniform
over the bins; `motion/sampler.py` holds the geometric sampler, the oracle's generator. A pick
has no parameters, and a stack takes its position from the object below, so only a place onto
a surface and a push are chosen over bins.

`propose` is what an agent calls, once per step. The learned generators are single shot as in
the paper: one proposal, no dry run (they ignore the one an agent may offer). The rule for
failures: parameters whose execution failed for good (`DO_NOT_RETRY`) are remembered with the
scene they failed in (`scene_key`: the held object and every pose to the centimetre); in that
unchanged scene the generator proposes its next-ranked parameters instead, and once every
choice has failed there it proposes its first choice again (a pick has only one), so that the
task level, which sees the same state come back, decides what to do. In a changed scene
everything may be proposed again.
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
        """Parameters for `action` in the scene `sg` (None when a generator has none to offer).

        `following` is the action the task planner expects next, where it knows one;
        `feasible`, when given, dry-runs a candidate (plans it without executing it)."""

    def observe(self, params: PrimitiveParams, outcome: Outcome) -> None:
        """What executing the proposal came to."""


def scene_key(sg: GeometricSceneGraph) -> tuple:
    """The scene as the failure memory compares scenes: what is held, every pose to the cm."""
    return sg.held, tuple((n.name, *(round(v * 100) for v in n.pose.position)) for n in sg.nodes)


class SingleShotMemory:
    """What every generator remembers within an episode: the parameters that failed for good,
    by the scene they failed in."""

    def __init__(self) -> None:
        self.failed: dict[tuple, set[PrimitiveParams]] = {}
        self._scene: tuple | None = None

    def reset(self, seed: int) -> None:
        self.failed = {}
        self._scene = None

    def untried(self, sg: GeometricSceneGraph, options: list) -> list:
        """The options that have not failed in this very scene (the one proposed in next)."""
        self._scene = scene_key(sg)
        failed = self.failed.get(self._scene, set())
        return [o for o in options if o not in failed]

    def observe(self, params: PrimitiveParams, outcome: Outcome) -> None:
        if outcome.status in DO_NOT_RETRY and self._scene is not None:
            self.failed.setdefault(self._scene, set()).add(params)


class _BinGenerator(SingleShotMemory):
    """Picks and stacks need no choice; everything else is the first of `ranked` not failed in
    this scene (the first of all when every one has)."""

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
            ranked: list[PrimitiveParams] = [PickParams(action.obj)]
        elif isinstance(action, Place) and action.target not in SURFACES:
            ranked = [PlaceParams(action.obj, action.target)]
        else:
            ranked = list(self.ranked(sg, intended_literal(action)))
        return (self.untried(sg, ranked) or ranked)[0]


def _all_params(kind: MotionPrimitive, subgoal: Literal, flat: list[int]):
    ny = BINS[kind][1]
    obj, target = subgoal.args
    return [params_for(kind, obj, target, (k // ny, k % ny)) for k in flat]


class LearnedMotion(_BinGenerator):
    """A trained motion network (GNN or MLP) per primitive, from checkpoint folders."""

    def __init__(self, name: str, folders: dict[MotionPrimitive, Path]) -> None:
        super().__init__()
        self.name = name
        self.nets = {
            kind: load_motion_net(folder, kind.value, name.split("_")[0])
            for kind, folder in folders.items()
        }

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
