"""Motion generators behind one interface: parameters for the action the task level chose.

`LearnedMotion` scores every bin pair with a trained network on the grounded scene graph (the
GNN or the MLP baseline); `RandomMotion` is the paper's single-shot random baseline, uniform
over the bins; `motion/sampler.py` holds the geometric sampler, the oracle's generator. A pick
has no parameters, and a stack takes its position from the object below, so only a place onto
a surface and a push are chosen over bins.

`propose` is what an agent calls, once per step. The learned generators are single shot as in
the paper: one proposal, no dry run (they ignore the one an agent may offer). Beyond the paper,
a generator made with `dry_runs` checks its proposal first: its first choice, then the others
not failed in this scene in its own order, up to `dry_runs` of them, each planned without
executing it (`Feasibility`: the motion planner in the robot's model of the scene, no domain
rule); the first that plans is proposed, else the first choice as without checks. The recovery rule
`failed_bins` (`hsgplan.domain.recovery`; without it a generator proposes its first choice in
every scene): parameters whose execution failed for good (`DO_NOT_RETRY`) are remembered with the
scene they failed in (`scene_key`: the held object and every pose to the centimetre). In a
scene where nothing has failed, a generator proposes its first choice (a network its
best-scored bins). In a scene where something has failed, it draws from its own distribution
over the bins not yet failed there (a network: the softmax of its scores; Random: uniform),
seeded per episode: a network's next-ranked bins are the failed bins' neighbours, which fail
for the same reason, so taking them in order wastes the steps a draw spreads over the places
the network still believes in. Once every choice has failed there it proposes its first
choice again (a pick has only one), so that the task level, which sees the same state come
back, decides what to do. In a changed scene everything may be proposed again.
"""

from __future__ import annotations

import random
from pathlib import Path

import torch
from torch_geometric.data import Batch

from hsgplan.domain.actions import Action, Pick, Place, Push, intended_literal, push_after
from hsgplan.domain.checks import read_json
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.parameters import (
    BINS,
    MotionPrimitive,
    PickParams,
    PlaceParams,
    PrimitiveParams,
    PushParams,
    params_for,
    place_centre,
    place_yaw,
)
from hsgplan.domain.predicates import Literal
from hsgplan.domain.recovery import ALL_RULES, RecoveryRules
from hsgplan.motion.interface import (
    DO_NOT_RETRY,
    PUSH_TRIES,
    Feasibility,
    SingleShotMemory,
    primitive_of,
)
from hsgplan.motion.models import load_motion_net
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.geometry import Pose
from hsgplan.scene_graph.grounding import check_subgoal, ground
from hsgplan.sim.outcome import Outcome, Status


class _BinGenerator(SingleShotMemory):
    """Picks and stacks need no choice; everything else is the first of `ranked` in a scene
    where nothing has failed, else a draw (`redraw`) from the ones not failed in this scene
    (the first of all when every one has).

    A spot in a prepush region can leave no push that works (the hand would hit a neighbour,
    the line is blocked). The recovery rule `push_give_up`: after `PUSH_TRIES` failed pushes of
    an object since it was put down, the generator gives up on the spot: it proposes nothing
    (the agent then takes the object up, as it does for the geometric sampler) and counts the
    place that put it there as failed in that scene, so that putting it down again draws
    another spot."""

    name = "bins"

    def __init__(self, rules: RecoveryRules = ALL_RULES, dry_runs: int = 0) -> None:
        super().__init__(rules)
        self.dry_runs = dry_runs
        self.rng = random.Random(f"{self.name}-motion-0")
        self._placed: dict[str, tuple[tuple, PlaceParams]] = {}
        self._push_failures: dict[str, int] = {}

    def reset(self, seed: int) -> None:
        super().reset(seed)
        self.rng = random.Random(f"{self.name}-motion-{seed}")
        self._placed, self._push_failures = {}, {}

    def observe(self, params: PrimitiveParams, outcome: Outcome) -> None:
        scene = self._scene
        super().observe(params, outcome)
        if isinstance(params, PushParams) and outcome.status in DO_NOT_RETRY:
            self._push_failures[params.obj] = self._push_failures.get(params.obj, 0) + 1
        elif outcome.status is Status.SUCCESS and not isinstance(params, PushParams):
            self._push_failures.pop(params.obj, None)
            self._placed.pop(params.obj, None)
            if isinstance(params, PlaceParams) and scene is not None:
                self._placed[params.obj] = (scene, params)

    def _give_up(self, obj: str) -> None:
        if obj in self._placed:
            scene, params = self._placed.pop(obj)
            self.failed.setdefault(scene, set()).add(params)
        self._push_failures.pop(obj, None)

    def ranked(self, sg: GeometricSceneGraph, subgoal: Literal) -> list[PlaceParams | PushParams]:
        raise NotImplementedError

    def for_push(
        self, sg: GeometricSceneGraph, ranked: list[PlaceParams | PushParams], push: Push
    ) -> list[PlaceParams | PushParams]:
        """`ranked`, a place's bins, ordered for the push that is to follow it (as it is)."""
        return ranked

    def redraw(self, untried: list[PlaceParams | PushParams]) -> PlaceParams | PushParams:
        """One of `untried` (in `ranked`'s order, never empty) after a failure in this scene."""
        return untried[0]

    def propose(
        self,
        sg: GeometricSceneGraph,
        action: Action,
        following: Action | None = None,
        feasible: Feasibility | None = None,
    ) -> PrimitiveParams | None:
        if isinstance(action, Pick):
            ranked: list[PrimitiveParams] = [PickParams(action.obj)]
        elif isinstance(action, Place) and action.target not in sg.world.surfaces:
            ranked = [PlaceParams(action.obj, action.target)]
        elif (
            isinstance(action, Push)
            and self.rules.push_give_up
            and self._push_failures.get(action.obj, 0) >= PUSH_TRIES
        ):
            self._give_up(action.obj)
            return None
        else:
            ranked = list(self.ranked(sg, intended_literal(action)))
            if _place_before_push(sg, action, following):
                ranked = self.for_push(sg, ranked, following)
        untried = self.untried(sg, ranked)
        take_first = not untried or len(untried) == len(ranked)  # none failed here, or all
        first = ranked[0] if take_first else self.redraw(untried)
        if not self.dry_runs or feasible is None or len(untried) < 2:
            return first
        options = [first, *(p for p in untried if p != first)][: self.dry_runs]
        return next((p for p in options if feasible(p)), first)


def _place_before_push(sg: GeometricSceneGraph, action: Action, following: Action | None) -> bool:
    """A place onto a shelf's prepush region, with the push of the same object into that shelf
    next (the task planner's plan says so)."""
    return following is not None and following == push_after(action, sg.world)


def placed_at(sg: GeometricSceneGraph, params: PlaceParams) -> GeometricSceneGraph:
    """The scene as it would be with the held object set down at a place bin's centre."""
    centre = place_centre(params.obj, params.target, params.x_bin, params.y_bin, sg.world)
    poses = {n.name: n.pose for n in sg.nodes}
    poses[params.obj] = Pose.from_xyz_yaw(*centre, place_yaw(params.target, sg.world))
    return GeometricSceneGraph.from_poses(poses, None, world=sg.world)


def _all_params(kind: MotionPrimitive, subgoal: Literal, flat: list[int]):
    ny = BINS[kind][1]
    obj, target = subgoal.args
    return [params_for(kind, obj, target, (k // ny, k % ny)) for k in flat]


# A place before a push weighs its bins by what the push network makes of them: of the bins the
# place network rates within PLACE_MARGIN of its best (predicted success), at most
# PLACE_CANDIDATES, the one leaving the push it rates highest. Both chosen on tuning seed 900;
# the shipped networks rate most bins of a free region within the margin, so there the count
# decides: the place network's 30 best bins, taken in the push network's order.
PLACE_MARGIN = 0.02
PLACE_CANDIDATES = 30


def _check_success_scores(folder: Path) -> None:
    """Refuse, in one line, a network whose scores are no chances of success: a place that
    looks ahead compares them across bins and scenes, which only the `bce` loss (every trial,
    success or not) makes meaningful; `ce`'s scores are each scene's softmax logits."""
    settings = folder / "train_config.json"
    loss = read_json(settings, "training settings").get("loss") if settings.exists() else None
    if loss != "bce":
        raise InvalidInputError(
            f"a place that looks ahead reads scores as chances of success, which networks "
            f"trained with loss bce give; '{folder}' was trained with {loss or 'an unknown loss'}"
        )


class LearnedMotion(_BinGenerator):
    """A trained motion network (GNN or MLP) per primitive, from checkpoint folders.

    Args:
        name: the model ("gnn" or "mlp"), which names its networks and seeds its draws.
        folders: a checkpoint folder per primitive.
        rules: the recovery rules in force.
        place_for_push: a place onto a shelf's prepush region, with the push into that shelf
            next, takes of its likeliest bins the one from which the push network rates its
            best push highest (beyond the paper, whose primitives are chosen one by one).
        dry_runs: proposals planned before one is made (0: single shot, as in the paper).
    """

    def __init__(
        self,
        name: str,
        folders: dict[MotionPrimitive, Path],
        rules: RecoveryRules = ALL_RULES,
        place_for_push: bool = False,
        dry_runs: int = 0,
    ) -> None:
        self.name = name
        super().__init__(rules, dry_runs)
        self.place_for_push = place_for_push
        self._weights: dict[PlaceParams | PushParams, float] = {}
        self._success: dict[PlaceParams | PushParams, float] = {}
        self.nets = {
            kind: load_motion_net(folder, kind.value, name.split("_")[0])
            for kind, folder in folders.items()
        }
        if place_for_push:
            for folder in folders.values():
                _check_success_scores(folder)

    def scores(self, sg: GeometricSceneGraph, subgoal: Literal) -> torch.Tensor:
        """Logits over the flattened bin pairs: [bins[0] * bins[1]]."""
        net = self.nets[primitive_of(subgoal)]
        with torch.inference_mode():
            return net(Batch.from_data_list([ground(sg, subgoal, net.config.features)]))[0]

    def ranked(self, sg: GeometricSceneGraph, subgoal: Literal) -> list[PlaceParams | PushParams]:
        scores = self.scores(sg, subgoal)
        order = torch.argsort(scores, descending=True, stable=True)
        params = _all_params(primitive_of(subgoal), subgoal, order.tolist())
        probs = torch.softmax(scores.double(), dim=0)[order].tolist()
        self._weights = dict(zip(params, probs, strict=True))
        success = torch.sigmoid(scores.double())[order].tolist()
        self._success = dict(zip(params, success, strict=True))
        return params

    def for_push(
        self, sg: GeometricSceneGraph, ranked: list[PlaceParams | PushParams], push: Push
    ) -> list[PlaceParams | PushParams]:
        net = self.nets.get(MotionPrimitive.PUSH)
        if not self.place_for_push or net is None:
            return ranked
        best = self._success[ranked[0]]
        near = [p for p in ranked if self._success[p] >= best - PLACE_MARGIN][:PLACE_CANDIDATES]
        if len(near) < 2:
            return ranked
        subgoal = intended_literal(push)
        graphs = [ground(placed_at(sg, p), subgoal, net.config.features) for p in near]
        with torch.inference_mode():
            pushes = net(Batch.from_data_list(graphs)).max(dim=1).values.tolist()
        # sorted is stable: among equal pushes the place network's order stands
        first = [near[k] for k in sorted(range(len(near)), key=lambda k: -pushes[k])]
        return first + ranked[len(near) :]

    def redraw(self, untried: list[PlaceParams | PushParams]) -> PlaceParams | PushParams:
        weights = [self._weights[p] for p in untried]
        if not sum(weights) > 0.0:  # every remaining bin underflowed: the best of them
            return untried[0]
        return self.rng.choices(untried, weights=weights)[0]


class RandomMotion(_BinGenerator):
    """Bins in a uniformly random order (seeded; `reset` reseeds it per episode)."""

    name = "random"

    def __init__(self, seed: int = 0, rules: RecoveryRules = ALL_RULES) -> None:
        super().__init__(rules)
        self.reset(seed)

    def ranked(self, sg: GeometricSceneGraph, subgoal: Literal) -> list[PlaceParams | PushParams]:
        check_subgoal(subgoal, sg)
        kind = primitive_of(subgoal)
        flat = list(range(BINS[kind][0] * BINS[kind][1]))
        self.rng.shuffle(flat)
        return _all_params(kind, subgoal, flat)
