"""The bin generators' rules for failures (`hsgplan.motion.generator`), on hand-made scene graphs
and a network stand-in with fixed scores: no checkpoint, no physics."""

from collections import Counter

import pytest
import torch

from hsgplan.domain.actions import Pick, Place, Push
from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.parameters import BINS, MotionPrimitive, PlaceParams, PushParams
from hsgplan.motion.generator import PUSH_TRIES, LearnedMotion, RandomMotion, _BinGenerator
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.outcome import Outcome, Status

HELD = "butter"
NX, NY = BINS[MotionPrimitive.PLACE]


class _FixedScores(LearnedMotion):
    """A learned generator whose network always scores the bins the same way."""

    def __init__(self, logits: torch.Tensor) -> None:
        self.name = "fixed"
        _BinGenerator.__init__(self)
        self._weights = {}
        self.logits = logits

    def scores(self, sg, subgoal) -> torch.Tensor:
        return self.logits


def _scene(held_at: tuple[float, float] = (0.0, 0.0), shift: float = 0.0) -> GeometricSceneGraph:
    """Cherries on the table, butter held (its pose is wherever the hand is)."""
    poses = {
        "cherries": Pose.from_xyz_yaw(
            0.42 + shift, 0.05, KITCHEN.object_type("cherries").height / 2, 0.0
        ),
        HELD: Pose.from_xyz_yaw(*held_at, 0.3, 0.0),
    }
    return GeometricSceneGraph.from_poses(poses, held=HELD, world=KITCHEN)


def _place(x: int, y: int) -> PlaceParams:
    return PlaceParams(HELD, "shelf_a", x, y)


def _logits(**bins: float) -> torch.Tensor:
    """Scores of -inf but for the named bins ('b_x_y' = score)."""
    logits = torch.full((NX * NY,), -1e9)
    for name, score in bins.items():
        _, x, y = name.split("_")
        logits[int(x) * NY + int(y)] = score
    return logits


def test_a_network_proposes_its_best_bins_and_after_a_failure_draws_from_its_own_distribution():
    # The failed bins' neighbour (0, 1) scores next best, but (5, 5) holds three times the
    # probability of (0, 1) once (0, 0) has failed: a draw, not the next in rank.
    logits = _logits(b_0_0=10.0, b_0_1=5.0, b_5_5=5.0 + float(torch.log(torch.tensor(3.0))))
    draws = Counter()
    for seed in range(200):
        motion = _FixedScores(logits)
        motion.reset(seed)
        first = motion.propose(_scene(), Place(HELD, "shelf_a"))
        assert first == _place(0, 0)  # single shot: the best
        motion.observe(first, Outcome(Status.NO_IK, "", 0.0))
        draws[motion.propose(_scene(), Place(HELD, "shelf_a"))] += 1
    assert set(draws) == {_place(0, 1), _place(5, 5)}
    assert 120 <= draws[_place(5, 5)] <= 180  # about three in four
    # the same episode seed, the same draw
    again = _FixedScores(logits)
    again.reset(7)
    again.observe(again.propose(_scene(), Place(HELD, "shelf_a")), Outcome(Status.NO_IK, "", 0.0))
    replay = _FixedScores(logits)
    replay.reset(7)
    replay.observe(replay.propose(_scene(), Place(HELD, "shelf_a")), Outcome(Status.NO_IK, "", 0))
    place = Place(HELD, "shelf_a")
    assert again.propose(_scene(), place) == replay.propose(_scene(), place)


def test_a_failure_is_remembered_by_the_scene_around_the_held_object():
    motion = _FixedScores(_logits(b_0_0=10.0, b_0_1=9.0))
    motion.reset(0)
    failed = motion.propose(_scene(held_at=(0.1, 0.1)), Place(HELD, "shelf_a"))
    motion.observe(failed, Outcome(Status.NO_IK, "", 0.0))
    # put down and taken up again: the hand holds it elsewhere, the rest is as it was
    assert motion.propose(_scene(held_at=(0.4, -0.2)), Place(HELD, "shelf_a")) == _place(0, 1)
    # something else moved: everything may be proposed again
    assert motion.propose(_scene(shift=0.05), Place(HELD, "shelf_a")) == failed


def test_after_failed_pushes_a_generator_gives_up_the_spot_and_draws_another_one_for_the_object():
    can = "cherries"
    pose = {can: Pose.from_xyz_yaw(0.30, 0.38, KITCHEN.object_type(can).height / 2, 0.0)}
    held, standing = (
        GeometricSceneGraph.from_poses(pose, held=can, world=KITCHEN),
        GeometricSceneGraph.from_poses(pose, world=KITCHEN),
    )
    motion = RandomMotion()
    motion.reset(0)
    spot = motion.propose(held, Place(can, "prepush_a"))
    motion.observe(spot, Outcome(Status.SUCCESS, "", 0.0))
    pushes = []
    for _ in range(PUSH_TRIES):
        pushes.append(motion.propose(standing, Push(can, "shelf_a")))
        assert isinstance(pushes[-1], PushParams)
        motion.observe(pushes[-1], Outcome(Status.NO_PATH, "", 0.0))
    assert motion.propose(standing, Push(can, "shelf_a")) is None  # the agent takes it up
    motion.observe(motion.propose(standing, Pick(can)), Outcome(Status.SUCCESS, "", 0.0))
    # put down again in the same scene: never the spot no push worked from
    for seed in range(30):
        motion.rng.seed(seed)
        assert motion.propose(held, Place(can, "prepush_a")) != spot
    # once put down elsewhere, pushes get their tries again
    motion.observe(motion.propose(held, Place(can, "prepush_a")), Outcome(Status.SUCCESS, "", 0))
    assert isinstance(motion.propose(standing, Push(can, "shelf_a")), PushParams)


def test_without_the_recovery_rules_a_generator_neither_remembers_nor_gives_up():
    from hsgplan.domain.recovery import RecoveryRules

    rules = RecoveryRules().without(["failed_bins", "push_give_up"])
    motion = _FixedScores(_logits(b_0_0=10.0, b_0_1=9.0))
    motion.rules = rules
    motion.reset(0)
    for _ in range(3):  # a network's best, whatever failed before
        proposal = motion.propose(_scene(), Place(HELD, "shelf_a"))
        assert proposal == _place(0, 0)
        motion.observe(proposal, Outcome(Status.NO_IK, "", 0.0))
    can = "cherries"
    pose = {can: Pose.from_xyz_yaw(0.30, 0.38, KITCHEN.object_type(can).height / 2, 0.0)}
    standing = GeometricSceneGraph.from_poses(pose, world=KITCHEN)
    random_motion = RandomMotion(rules=rules)
    random_motion.reset(0)
    for _ in range(PUSH_TRIES + 2):  # a fresh uniform draw every step, never giving up
        push = random_motion.propose(standing, Push(can, "shelf_a"))
        assert isinstance(push, PushParams)
        random_motion.observe(push, Outcome(Status.NO_PATH, "", 0.0))


class _PushStandIn:
    """A push network's stand-in: the k-th scene it is shown rates its best push `best[k]`;
    it keeps the scenes it saw."""

    class config:
        features = "names"

    def __init__(self, best: list[float]) -> None:
        self.best, self.seen = best, []

    def __call__(self, batch) -> torch.Tensor:
        self.seen.append(batch)
        return torch.tensor([[v, v - 1.0] for v in self.best[: batch.num_graphs]])


def _can_held(place_for_push: bool, push_best: list[float]) -> tuple[LearnedMotion, _PushStandIn]:
    # sigmoid(3.0) and sigmoid(2.95) are 0.0023 apart, sigmoid(0.0) is 0.45 below: two candidates
    gen = _FixedScores(_logits(b_0_0=3.0, b_0_8=2.95, b_5_5=0.0))
    gen.place_for_push, gen._success = place_for_push, {}
    gen.nets = {MotionPrimitive.PUSH: _PushStandIn(push_best)}
    return gen, gen.nets[MotionPrimitive.PUSH]


def _can_scene() -> GeometricSceneGraph:
    poses = {
        "cherries": Pose.from_xyz_yaw(0.42, 0.05, KITCHEN.object_type("cherries").height / 2),
        "tomato_soup": Pose.from_xyz_yaw(0.0, 0.0, 0.3),
    }
    return GeometricSceneGraph.from_poses(poses, held="tomato_soup", world=KITCHEN)


def test_a_place_before_a_push_takes_of_its_likeliest_bins_the_one_the_push_network_rates_best():
    place, push = Place("tomato_soup", "prepush_a"), Push("tomato_soup", "shelf_a")
    gen, net = _can_held(True, push_best=[0.1, 0.9])
    chosen = gen.propose(_can_scene(), place, following=push)
    assert chosen == PlaceParams("tomato_soup", "prepush_a", 0, 8)
    (batch,) = net.seen  # one batch: the two bins within the margin, (5, 5) left out
    assert batch.num_graphs == 2


def test_a_place_asks_the_push_network_only_before_its_own_push_and_only_when_told_to():
    place, push = Place("tomato_soup", "prepush_a"), Push("tomato_soup", "shelf_a")
    best = PlaceParams("tomato_soup", "prepush_a", 0, 0)
    off, off_net = _can_held(False, push_best=[0.1, 0.9])
    assert off.propose(_can_scene(), place, following=push) == best and not off_net.seen
    on, on_net = _can_held(True, push_best=[0.1, 0.9])
    assert on.propose(_can_scene(), place, following=None) == best
    assert on.propose(_can_scene(), place, following=Push("cherries", "shelf_a")) == best
    assert not on_net.seen
    # equal pushes keep the place network's order
    tie, _ = _can_held(True, push_best=[0.5, 0.5])
    assert tie.propose(_can_scene(), place, following=push) == best


def test_the_scene_after_a_place_has_the_object_set_down_at_the_bins_centre():
    from hsgplan.domain.parameters import place_xy
    from hsgplan.motion.generator import placed_at

    params = PlaceParams("tomato_soup", "prepush_a", 3, 7)
    after = placed_at(_can_scene(), params)
    assert after.held is None
    pose = next(n.pose for n in after.nodes if n.name == "tomato_soup").position
    x, y = place_xy("tomato_soup", "prepush_a", 3, 7, KITCHEN)
    z = KITCHEN.surface_rect("prepush_a").z + KITCHEN.object_type("tomato_soup").height / 2
    assert pose == pytest.approx((x, y, z))
    assert next(n.pose for n in after.nodes if n.name == "cherries") == next(
        n.pose for n in _can_scene().nodes if n.name == "cherries"
    )


class _Planner:
    """A dry run's stand-in: the bins it plans, and every call it was asked."""

    def __init__(self, plans: set[PlaceParams]) -> None:
        self.plans, self.asked = plans, []

    def __call__(self, params) -> bool:
        self.asked.append(params)
        return params in self.plans


def test_a_checked_generator_proposes_its_first_choice_that_plans_within_its_budget():
    logits = _logits(b_0_0=10.0, b_0_1=9.0, b_5_5=8.0, b_7_2=7.0)
    place = Place(HELD, "shelf_a")
    motion = _FixedScores(logits)
    motion.dry_runs = 3
    motion.reset(0)
    planner = _Planner({_place(5, 5), _place(7, 2)})
    assert motion.propose(_scene(), place, feasible=planner) == _place(5, 5)
    assert planner.asked == [_place(0, 0), _place(0, 1), _place(5, 5)]  # in the network's order
    # nothing within the budget plans: the first choice, as without checks
    late = _Planner({_place(7, 2)})
    assert motion.propose(_scene(), place, feasible=late) == _place(0, 0)
    assert len(late.asked) == 3
    # single shot: a generator without dry runs never asks, nor does a checked one not offered
    # a dry run
    single = _FixedScores(logits)
    single.reset(0)
    assert single.propose(_scene(), place, feasible=planner) == _place(0, 0)
    assert len(planner.asked) == 3
    assert motion.propose(_scene(), place) == _place(0, 0)


def test_a_checked_generator_starts_from_its_draw_after_a_failure_and_skips_failed_bins():
    logits = _logits(b_0_0=10.0, b_0_1=9.0, b_5_5=8.0)
    place = Place(HELD, "shelf_a")
    motion = _FixedScores(logits)
    motion.dry_runs = 30
    motion.reset(3)
    motion.observe(motion.propose(_scene(), place), Outcome(Status.NO_IK, "", 0.0))
    twin = _FixedScores(logits)
    twin.reset(3)
    twin.observe(twin.propose(_scene(), place), Outcome(Status.NO_IK, "", 0.0))
    drawn = twin.propose(_scene(), place)  # what the unchecked generator draws now
    planner = _Planner(set())
    assert motion.propose(_scene(), place, feasible=planner) == drawn
    assert planner.asked[0] == drawn
    assert _place(0, 0) not in planner.asked
    assert len(planner.asked) == motion.dry_runs  # the budget, of the bins not failed
