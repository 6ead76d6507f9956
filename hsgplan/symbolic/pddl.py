"""The kitchen-storage domain in PDDL, built with unified-planning.

It states the rules of `transition.py` in a form Fast Downward solves. Counting is encoded
with number objects `n0..nK` and a static successor relation, since classical planners have
no arithmetic: `count(s, n)` is how many objects rest on surface s, `icount(sh, n)` how many
are inside shelf sh, and `level(o, n)` the height of o in its tower. Static facts (`cap`,
`icap`, `maxlevel`, `carrier`, `fits`, `prepush`) come from the world's derived limits.
Pick and place come in two forms (surface / object), since only the latter frees or covers
the object below; `decode` maps the grounded actions back to `Pick` / `Place` / `Push`.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from unified_planning.model import Fluent, InstantaneousAction, Object, Problem
from unified_planning.shortcuts import BoolType, Not, UserType

from hsgplan.domain.actions import Action, Pick, Place, Push
from hsgplan.domain.goals import Goal
from hsgplan.domain.predicates import Literal, Predicate
from hsgplan.domain.scene import World
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph

ENTITY = UserType("entity")
OBJ = UserType("obj", ENTITY)
SURFACE = UserType("surface", ENTITY)
REGION = UserType("region", SURFACE)
SHELF = UserType("shelf", SURFACE)
NUM = UserType("num")

_B = BoolType()
ON = Fluent("on", _B, o=OBJ, x=ENTITY)
INSIDE = Fluent("inside", _B, o=OBJ, s=SHELF)
INGRASP = Fluent("ingrasp", _B, o=OBJ)
CLEAR = Fluent("clear", _B, o=OBJ)
HANDEMPTY = Fluent("handempty", _B)
COUNT = Fluent("count", _B, s=SURFACE, n=NUM)
ICOUNT = Fluent("icount", _B, s=SHELF, n=NUM)
LEVEL = Fluent("level", _B, o=OBJ, n=NUM)
SUCC = Fluent("succ", _B, a=NUM, b=NUM)
CAP = Fluent("cap", _B, s=SURFACE, n=NUM)
ICAP = Fluent("icap", _B, s=SHELF, n=NUM)
MAXLEVEL = Fluent("maxlevel", _B, n=NUM)
CARRIER = Fluent("carrier", _B, o=OBJ)
FITS = Fluent("fits", _B, o=OBJ, s=SHELF)
PREPUSH = Fluent("prepush", _B, r=REGION, s=SHELF)
# Ground actions a search-based planner has found no motion for, left out of its next plan.
BANNED_PICK = Fluent("banned_pick", _B, o=OBJ)
BANNED_PLACE = Fluent("banned_place", _B, o=OBJ, x=ENTITY)
BANNED_PUSH = Fluent("banned_push", _B, o=OBJ, s=SHELF)
FLUENTS = (ON, INSIDE, INGRASP, CLEAR, HANDEMPTY, COUNT, ICOUNT, LEVEL)
BANS = (BANNED_PICK, BANNED_PLACE, BANNED_PUSH)
STATICS = (SUCC, CAP, ICAP, MAXLEVEL, CARRIER, FITS, PREPUSH)

N1 = Object("n1", NUM)


def numbers(world: World) -> list[Object]:
    """n0, n1, ... up to the largest count the world's limits need."""
    counts = [*world.surface_capacity.values(), *world.interior_capacity.values()]
    return [Object(f"n{i}", NUM) for i in range(max(*counts, world.max_tower_levels) + 1)]


def _actions(bans: bool = False) -> list[InstantaneousAction]:
    """The domain's actions; with `bans`, each also requires its ground action not banned."""

    def allowed(fluent, *args) -> list:
        return [Not(fluent(*args))] if bans else []

    pick_s = InstantaneousAction("pick_from_surface", o=OBJ, s=SURFACE, n=NUM, m=NUM)
    o, s, n, m = pick_s.parameters
    for c in (ON(o, s), CLEAR(o), HANDEMPTY, COUNT(s, m), SUCC(n, m), *allowed(BANNED_PICK, o)):
        pick_s.add_precondition(c)
    for f, v in (
        (ON(o, s), False),
        (CLEAR(o), False),
        (HANDEMPTY, False),
        (INGRASP(o), True),
        (COUNT(s, m), False),
        (COUNT(s, n), True),
        (LEVEL(o, N1), False),
    ):
        pick_s.add_effect(f, v)

    pick_o = InstantaneousAction("pick_from_object", o=OBJ, b=OBJ, k=NUM)
    o, b, k = pick_o.parameters
    for c in (ON(o, b), CLEAR(o), HANDEMPTY, LEVEL(o, k), *allowed(BANNED_PICK, o)):
        pick_o.add_precondition(c)
    for f, v in (
        (ON(o, b), False),
        (CLEAR(o), False),
        (HANDEMPTY, False),
        (INGRASP(o), True),
        (CLEAR(b), True),
        (LEVEL(o, k), False),
    ):
        pick_o.add_effect(f, v)

    place_s = InstantaneousAction("place_on_surface", o=OBJ, s=SURFACE, n=NUM, m=NUM)
    o, s, n, m = place_s.parameters
    for c in (INGRASP(o), COUNT(s, n), SUCC(n, m), CAP(s, m), *allowed(BANNED_PLACE, o, s)):
        place_s.add_precondition(c)
    for f, v in (
        (ON(o, s), True),
        (CLEAR(o), True),
        (HANDEMPTY, True),
        (INGRASP(o), False),
        (COUNT(s, n), False),
        (COUNT(s, m), True),
        (LEVEL(o, N1), True),
    ):
        place_s.add_effect(f, v)

    place_o = InstantaneousAction("place_on_object", o=OBJ, b=OBJ, k=NUM, k2=NUM)
    o, b, k, k2 = place_o.parameters
    for c in (
        INGRASP(o),
        CLEAR(b),
        CARRIER(b),
        LEVEL(b, k),
        SUCC(k, k2),
        MAXLEVEL(k2),
        *allowed(BANNED_PLACE, o, b),
    ):
        place_o.add_precondition(c)
    for f, v in (
        (ON(o, b), True),
        (CLEAR(o), True),
        (HANDEMPTY, True),
        (INGRASP(o), False),
        (CLEAR(b), False),
        (LEVEL(o, k2), True),
    ):
        place_o.add_effect(f, v)

    push = InstantaneousAction("push", o=OBJ, r=REGION, s=SHELF, n=NUM, m=NUM, p=NUM, q=NUM)
    o, r, s, n, m, p, q = push.parameters
    for c in (
        ON(o, r),
        PREPUSH(r, s),
        CLEAR(o),
        HANDEMPTY,
        FITS(o, s),
        COUNT(r, m),
        SUCC(n, m),
        ICOUNT(s, p),
        SUCC(p, q),
        ICAP(s, q),
        *allowed(BANNED_PUSH, o, s),
    ):
        push.add_precondition(c)
    for f, v in (
        (ON(o, r), False),
        (INSIDE(o, s), True),
        (CLEAR(o), False),
        (COUNT(r, m), False),
        (COUNT(r, n), True),
        (ICOUNT(s, p), False),
        (ICOUNT(s, q), True),
        (LEVEL(o, N1), False),
    ):
        push.add_effect(f, v)
    return [pick_s, pick_o, place_s, place_o, push]


ACTIONS = _actions()
ACTIONS_WITH_BANS = _actions(bans=True)


@dataclass(frozen=True)
class PddlProblem:
    """A unified-planning problem and the entity objects it was built with."""

    problem: Problem
    entities: dict[str, Object]


def build_problem(
    state: SymbolicSceneGraph, goal: Goal, banned: Iterable[Action] = ()
) -> PddlProblem:
    """The planning problem of reaching `goal` from `state` without any `banned` action."""
    banned = tuple(banned)
    problem = Problem("kitchen_storage")
    for f in FLUENTS + STATICS + (BANS if banned else ()):
        problem.add_fluent(f, default_initial_value=False)
    for a in ACTIONS_WITH_BANS if banned else ACTIONS:
        problem.add_action(a)
    world, nums = state.world, numbers(state.world)
    ents: dict[str, Object] = {o: Object(o, OBJ) for o in state.objects}
    ents |= {r: Object(r, REGION) for r in world.regions}
    ents |= {s: Object(s, SHELF) for s in world.shelves}
    problem.add_objects(list(ents.values()) + nums)
    init = problem.set_initial_value
    for a, b in zip(nums, nums[1:], strict=False):
        init(SUCC(a, b), True)
    for s, c in world.surface_capacity.items():
        for i in range(1, c + 1):
            init(CAP(ents[s], nums[i]), True)
        init(COUNT(ents[s], nums[len(state.resting_on(s))]), True)
    for s, c in world.interior_capacity.items():
        for i in range(1, c + 1):
            init(ICAP(ents[s], nums[i]), True)
        init(ICOUNT(ents[s], nums[len(state.inside(s))]), True)
        init(PREPUSH(ents[world.shelves[s].prepush], ents[s]), True)
    for i in range(1, world.max_tower_levels + 1):
        init(MAXLEVEL(nums[i]), True)
    for o in state.objects:
        t = world.object_type(o).name
        if world.can_support(t):
            init(CARRIER(ents[o]), True)
        for s in world.shelves:
            if world.fits_inside(t, s):
                init(FITS(ents[o], ents[s]), True)
        if state.level(o):
            init(LEVEL(ents[o], nums[state.level(o)]), True)
    if state.held() is None:
        init(HANDEMPTY, True)
    for lit in state.literals:
        init(_fluent(lit, ents), True)
    for a in banned:
        init(_ban(a, ents), True)
    for lit in goal.literals:
        expr = _fluent(lit, ents)
        problem.add_goal(expr if lit.positive else Not(expr))
    return PddlProblem(problem, ents)


def _fluent(lit: Literal, ents: dict[str, Object]):
    fluent = {
        Predicate.ON: ON,
        Predicate.IN: INSIDE,
        Predicate.IN_GRASP: INGRASP,
        Predicate.CLEAR: CLEAR,
    }[lit.predicate]
    return fluent(*(ents[a] for a in lit.args))


def _ban(action: Action, ents: dict[str, Object]):
    if isinstance(action, Pick):
        return BANNED_PICK(ents[action.obj])
    if isinstance(action, Place):
        return BANNED_PLACE(ents[action.obj], ents[action.target])
    return BANNED_PUSH(ents[action.obj], ents[action.shelf])


def decode(name: str, args: list[str]) -> Action:
    """A grounded PDDL action (name and object names) as a domain action."""
    if name.startswith("pick"):
        return Pick(args[0])
    if name.startswith("place"):
        return Place(args[0], args[1])
    if name == "push":
        return Push(args[0], args[2])
    raise ValueError(f"unknown PDDL action '{name}'")


def to_pddl_text(state: SymbolicSceneGraph, goal: Goal) -> tuple[str, str]:
    """The domain and problem as PDDL text, for reading or for another planner."""
    from unified_planning.io import PDDLWriter

    writer = PDDLWriter(build_problem(state, goal).problem)
    return writer.get_domain(), writer.get_problem()
