"""What a primitive's execution came to, and the one judge of it (`judge`).

Every executed step is judged by `judge` on the simulator's scene graphs before and after it,
whatever the robot saw: under the ground truth that verdict is the step's outcome; seeing
through cameras the robot decides on its own reading (`sim.believing`) and the env keeps the
judge's verdict for the record (`KitchenStorageEnv.verdicts`, read after the episode).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

from hsgplan.domain.predicates import Literal, Predicate
from hsgplan.domain.scene import World
from hsgplan.domain.world import Kind
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.geometry import Pose, rotation_apart
from hsgplan.scene_graph.symbol_mapping import AnomalyKind, map_symbols

# Another object that moves further than this (horizontally) was disturbed by the primitive:
# the judge's, for every observer.
DISTURB_TOL = 0.02
# The robot's own reading of the same, seeing through cameras (what it decides, retries and
# stops on; never the judge's): judged on f_p's looks before and after the step, of objects
# both looks saw from several views: a move the looks cannot tell from their own spread is none.
# On the tuning seeds (`eval world --perception rgb --protocol paper --sizes 4-6 --goals 30
# --seed 900`), objects a step truly left still (none moved 5 mm) seemed to move up to 5.2 cm
# between two looks, beyond 2 cm in 13 of 825 steps (`still_seen_moved` in summary.json).
SEEN_DISTURB_TOL = 0.06
# Any object but the one acted on that moves further than this during a primitive is recorded
# as disturbed by it (the record's, not the status's: nudges under DISTURB_TOL are recorded).
DISTURB_RECORD = 0.005


class Status(StrEnum):
    SUCCESS = "success"
    INVALID = "invalid"  # the parameters cannot apply to this scene (nothing was moved)
    NO_IK = "no_ik"  # no collision-free arm configuration for a needed pose
    NO_PATH = "no_path"  # the motion planner found no path, or a push line left the reach
    DROPPED = "dropped"  # the object is not in the gripper after a pick
    KNOCKED_OVER = "knocked_over"  # some object toppled
    OFF_TABLE = "off_table"  # some object fell off the table
    DISTURBED = "disturbed"  # another object was moved out of place
    EFFECT_NOT_REACHED = "effect_not_reached"  # the intended predicate does not hold
    # Motion data only (`hsgplan.data.motion_trials`): the place reached its effect but left an
    # object on that surface, or the placed one, that can no longer be taken up.
    BLOCKS_PICK = "blocks_pick"
    # New statuses go last: stored motion data holds a status as its index in this order.
    BLOCKED = "blocked"  # the arm was stopped short by what it met, and the effect not reached


@dataclass(frozen=True)
class Outcome:
    """The result of one primitive: its status, a sentence on why, and its wall time
    (`relooks`: the looks a camera observer took first, from out of the cameras' way, whose
    time is in it)."""

    status: Status
    detail: str
    seconds: float
    relooks: int = 0

    @property
    def ok(self) -> bool:
        return self.status is Status.SUCCESS


@dataclass(frozen=True)
class Disturbance:
    """An object a primitive moved that it was not acting on, how far (m), and in which of the
    primitive's phases it first moved that far ("" where no phase was told)."""

    obj: str
    moved: float
    phase: str = ""


def disturbances(
    before: dict[str, Pose],
    after: dict[str, Pose],
    acted_on: str,
    phases: list[tuple[str, dict[str, Pose]]] | tuple = (),
) -> tuple[Disturbance, ...]:
    """The objects other than `acted_on` that moved more than DISTURB_RECORD between two sets
    of poses (the simulator's: what a primitive truly did, for the episode's record), each
    with the first of `phases` (a phase's name and the poses as it ended) by whose end it had
    moved more than DISTURB_RECORD."""
    out = []
    for o in sorted(before):
        if o == acted_on or o not in after:
            continue
        moved = round(before[o].distance(after[o]), 4)
        if moved > DISTURB_RECORD:
            first = (n for n, poses in phases if before[o].distance(poses[o]) > DISTURB_RECORD)
            out.append(Disturbance(o, moved, next(first, "")))
    return tuple(out)


# A belief this far from the truth is off: f_p's targets for one object's pose (docs/perception.md).
BELIEF_OFF = 0.01  # m
BELIEF_TURNED = 10.0  # degrees


@dataclass(frozen=True)
class BeliefError:
    """How far the belief a primitive was planned on had an object it acted on (its own, or
    the object it places onto) from the simulator's pose: metres, and degrees up to what the
    object's shape cannot tell apart. The record's, never the robot's."""

    obj: str
    off: float
    turned: float

    @property
    def beyond(self) -> bool:
        return self.off > BELIEF_OFF or self.turned > BELIEF_TURNED


def belief_errors(
    believed: GeometricSceneGraph,
    truth: dict[str, Pose],
    objects: tuple[str, ...],
    world: World,
) -> tuple[BeliefError, ...]:
    """The belief's error of each of `objects` that it and the simulator both hold."""
    return tuple(
        BeliefError(
            o,
            round(believed.pose(o).distance(truth[o]), 4),
            round(
                rotation_apart(believed.pose(o), truth[o], world.object_type(o).kind is Kind.CAN),
                2,
            ),
        )
        for o in objects
        if o in believed.objects and o in truth
    )


def dragged(phases: list[tuple[str, dict[str, Pose]]], after: dict[str, Pose], obj: str) -> float:
    """How far (m) a place's object moved from when the hand let it go (the end of its
    `release` phase) to the primitive's end: the retreat dragging it. 0 for a pick or a push
    (whose object slides on after the stroke by design), or where no phase was told."""
    let_go = next((poses for name, poses in phases if name == "release"), None)
    if let_go is None or obj not in let_go or obj not in after:
        return 0.0
    return round(let_go[obj].distance(after[obj]), 4)


def largest_move(
    before: GeometricSceneGraph,
    after: GeometricSceneGraph,
    acted_on: str,
    among: frozenset[str] | None = None,
) -> float:
    """How far (m) the object that moved most between two scene graphs moved, of those in
    both (and in `among`, if given) but `acted_on`; 0 if none."""
    return max(
        (
            before.pose(o).distance(after.pose(o))
            for o in after.objects
            if o != acted_on and o in before.objects and (among is None or o in among)
        ),
        default=0.0,
    )


@dataclass(frozen=True)
class Verdict:
    """The judge's word on one executed step: its status on the simulator's state, and why."""

    status: Status
    detail: str = ""

    @property
    def ok(self) -> bool:
        return self.status is Status.SUCCESS


def judge(
    before: GeometricSceneGraph,
    after: GeometricSceneGraph,
    obj: str,
    expected: Literal,
    stopped: str | None = None,
) -> Verdict:
    """The one judge of an executed step, on the simulator's scene graphs before and after it
    (in which an object is held when it rose with the hand, whatever holds it:
    `Scene.held`): an object toppled or off the table, the intended literal missed (a pick's
    object not held: dropped), another object moved more than DISTURB_TOL or out of its
    place; an arm stopped short (`stopped`, from its encoders) where the effect was missed is
    blocked."""
    return Verdict(*stopped_outcome(*compare(before, after, obj, expected), stopped))


def stopped_outcome(status: Status, detail: str, stopped: str | None) -> tuple[Status, str]:
    """A primitive whose arm was stopped short and whose effect does not hold failed because
    it was stopped (unless something fell or toppled, which says more)."""
    if stopped is None or status in (Status.SUCCESS, Status.KNOCKED_OVER, Status.OFF_TABLE):
        return status, detail
    return Status.BLOCKED, stopped


def compare(
    before: GeometricSceneGraph,
    after: GeometricSceneGraph,
    obj: str,
    expected: Literal,
    tolerance: float = DISTURB_TOL,
    sure: frozenset[str] | None = None,
    judged: frozenset[str] | None = None,
) -> tuple[Status, str]:
    """A primitive's outcome from the scene graphs before and after it: the simulator's, or
    what a camera observer believed before and believes after (objects in one and not the
    other are not compared). Another object is disturbed if its symbolic location changed or
    it moved further than `tolerance` (SEEN_DISTURB_TOL for a belief); of a belief, only the
    objects it is `sure` of in both looks are judged by distance (None: every object). Only
    the objects in `judged` can be found disturbed (None: every object)."""
    mapping = map_symbols(after)
    prior_mapping = map_symbols(before)
    prior = prior_mapping.state
    known = {(a.obj, a.kind) for a in prior_mapping.anomalies}
    fresh = [a for a in mapping.anomalies if (a.obj, a.kind) not in known]
    anomalies = sorted(fresh, key=lambda a: a.obj != obj)
    for a in anomalies:
        if a.kind is AnomalyKind.TOPPLED:
            return Status.KNOCKED_OVER, f"'{a.obj}' toppled: {a.detail}"
        if a.kind is AnomalyKind.OFF_TABLE:
            return Status.OFF_TABLE, f"'{a.obj}' fell off the table"
    if not mapping.state.holds(expected):
        status = (
            Status.DROPPED
            if expected.predicate is Predicate.IN_GRASP
            else (Status.EFFECT_NOT_REACHED)
        )
        return status, f"'{expected}' does not hold: '{mapping.state.location(obj)}' instead"
    for o in after.objects:
        if o == obj or o not in before.objects or (judged is not None and o not in judged):
            continue
        moved = before.pose(o).distance(after.pose(o))
        far = moved > tolerance and (sure is None or o in sure)
        if far or prior.location(o) != mapping.state.location(o):
            return Status.DISTURBED, f"'{o}' moved {100 * moved:.1f} cm"
    for a in anomalies:
        return Status.EFFECT_NOT_REACHED, f"'{a.obj}': {a.kind.value}, {a.detail}"
    return Status.SUCCESS, ""
