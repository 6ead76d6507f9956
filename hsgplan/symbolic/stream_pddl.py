"""The kitchen-storage domain at PDDLStream's level: continuous values are PDDL objects.

Unlike `pddl.py`, which abstracts the geometry away, this domain plans over object poses
(`?p`), grasps (`?g`), arm configurations (`?q`) and push parameters (`?u`), each an object
that a stream produced, with the facts the stream certified: `(pose o p)`, `(supported o p s)`
(p rests on surface s), `(stacked o p b pb)` (p rests on b at pb), `(inside o p s)` (p is in
shelf s's interior), `(grasp o g)`, `(kin o p g q)` (the arm at q holds o at p with g) and
`(pushable o p s u p2 q)` (the push u, starting at q, moves o from p to p2 inside s).
`(collide o p o2 p2)` records that the collision test (PDDLStream's `CFree`) failed for two
objects at those poses. The fluents are `(atpose o p)`, `(atgrasp o g)` and `(handempty)`.

The goal language's predicates are derived (axioms) from the poses, as PDDLStream writes them:
`on` from `supported` or `stacked` at the current poses, `in` from `inside`, `ingrasp` from
`atgrasp`, `clear` from nothing being on the object, it not being held and not in a shelf; and
`unsafepose` (some other object stands where a pose would collide with it) keeps places and
pushes clear of what is already there.

PDDLStream's examples certify the pairs that are free, `(CFree o p o2 p2)`, and derive
`unsafepose` from `(not (CFree ...))`. Every pair of poses is tested here as soon as both
exist, so the two say the same; but the free pairs are nearly all pairs, quadratic in the poses
(measured: 207,000 facts at the second level of a 6-object goal, against 20,000 listing the
colliding pairs instead). The baseline lists the colliding pairs, `(collide o p o2 p2)`.

Capacities, towers and fits are not counted here as `pddl.py` counts them: they follow from
which poses the streams produce and which collide.
"""

from __future__ import annotations

from collections.abc import Iterable

from hsgplan.domain.goals import Goal
from hsgplan.domain.predicates import Literal, Predicate

DOMAIN = """\
(define (domain kitchen-storage-streams)
  (:requirements :strips :typing :equality :negative-preconditions
                 :disjunctive-preconditions :existential-preconditions :derived-predicates)
  (:types obj surface - entity
          pose grasp conf push)
  (:predicates
    (pose ?o - obj ?p - pose)
    (supported ?o - obj ?p - pose ?s - entity)
    (stacked ?o - obj ?p - pose ?b - entity ?pb - pose)
    (inside ?o - obj ?p - pose ?s - surface)
    (grasp ?o - obj ?g - grasp)
    (kin ?o - obj ?p - pose ?g - grasp ?q - conf)
    (pushable ?o - obj ?p - pose ?s - surface ?u - push ?p2 - pose ?q - conf)
    (collide ?o - obj ?p - pose ?o2 - obj ?p2 - pose)
    (atpose ?o - entity ?p - pose)
    (atgrasp ?o - obj ?g - grasp)
    (handempty)
    (on ?o - obj ?x - entity)
    (in ?o - obj ?s - surface)
    (ingrasp ?o - obj)
    (covered ?o - obj)
    (shelved ?o - obj)
    (clear ?o - obj)
    (unsafepose ?o - obj ?p - pose))

  (:derived (on ?o - obj ?x - entity)
    (or (exists (?p - pose) (and (supported ?o ?p ?x) (atpose ?o ?p)))
        (exists (?p ?pb - pose) (and (stacked ?o ?p ?x ?pb) (atpose ?o ?p) (atpose ?x ?pb)))))
  (:derived (in ?o - obj ?s - surface)
    (exists (?p - pose) (and (inside ?o ?p ?s) (atpose ?o ?p))))
  (:derived (ingrasp ?o - obj) (exists (?g - grasp) (atgrasp ?o ?g)))
  (:derived (covered ?b - obj) (exists (?o - obj) (on ?o ?b)))
  (:derived (shelved ?o - obj) (exists (?s - surface) (in ?o ?s)))
  (:derived (clear ?o - obj)
    (and (not (covered ?o)) (not (ingrasp ?o)) (not (shelved ?o))))
  (:derived (unsafepose ?o - obj ?p - pose)
    (exists (?o2 - obj ?p2 - pose) (and (collide ?o ?p ?o2 ?p2) (atpose ?o2 ?p2))))

  (:action pick
    :parameters (?o - obj ?p - pose ?g - grasp ?q - conf)
    :precondition (and (kin ?o ?p ?g ?q) (atpose ?o ?p) (handempty) (not (covered ?o)))
    :effect (and (atgrasp ?o ?g) (not (atpose ?o ?p)) (not (handempty))))

  (:action place
    :parameters (?o - obj ?p - pose ?s - surface ?g - grasp ?q - conf)
    :precondition (and (kin ?o ?p ?g ?q) (supported ?o ?p ?s) (atgrasp ?o ?g)
                       (not (unsafepose ?o ?p)))
    :effect (and (atpose ?o ?p) (handempty) (not (atgrasp ?o ?g))))

  (:action stack
    :parameters (?o - obj ?p - pose ?b - obj ?pb - pose ?g - grasp ?q - conf)
    :precondition (and (kin ?o ?p ?g ?q) (stacked ?o ?p ?b ?pb) (atpose ?b ?pb)
                       (atgrasp ?o ?g) (not (covered ?b)) (not (unsafepose ?o ?p)))
    :effect (and (atpose ?o ?p) (handempty) (not (atgrasp ?o ?g))))

  (:action push
    :parameters (?o - obj ?p - pose ?s - surface ?u - push ?p2 - pose ?q - conf)
    :precondition (and (pushable ?o ?p ?s ?u ?p2 ?q) (atpose ?o ?p) (handempty)
                       (not (covered ?o)) (not (unsafepose ?o ?p2)))
    :effect (and (atpose ?o ?p2) (not (atpose ?o ?p)))))
"""

# Fast Downward's search as the project's (`SATISFICING_SEARCH`), but with the FF heuristic's
# negated axioms over-approximated: computed exactly (the default), the negation of
# `unsafepose`, a conjunction over every pose it could collide with, made the heuristic's set-up
# run out of 19 s and 800 MB on a 6-object problem of 20,000 facts; approximated, the search
# proved that problem unsolvable in 5 s.
STREAM_SEARCH = "let(hff,ff(axioms=approximate_negative),lazy_wastar([hff],preferred=[hff],w=2))"

# PDDL type of each kind of object a problem declares.
TYPES = ("obj", "surface", "pose", "grasp", "conf", "push")

Fact = tuple[str, ...]  # a ground atom: predicate name, then argument names

_GOAL_ATOM = {
    Predicate.ON: "on",
    Predicate.IN: "in",
    Predicate.IN_GRASP: "ingrasp",
    Predicate.CLEAR: "clear",
}


def atom_text(fact: Fact) -> str:
    return f"({' '.join(fact)})"


def goal_text(literal: Literal) -> str:
    atom = atom_text((_GOAL_ATOM[literal.predicate], *literal.args))
    return atom if literal.positive else f"(not {atom})"


def problem_text(objects: dict[str, Iterable[str]], init: Iterable[Fact], goal: Goal) -> str:
    """The problem: `objects` maps a PDDL type (`TYPES`) to the names of that type; `init`
    holds every certified fact and the fluents of the initial state."""
    declared = "\n    ".join(f"{' '.join(names)} - {t}" for t, names in objects.items() if names)
    facts = "\n    ".join(atom_text(f) for f in init)
    goals = "\n    ".join(goal_text(lit) for lit in goal.sorted_literals())
    return (
        "(define (problem kitchen-storage-streams-problem)\n"
        "  (:domain kitchen-storage-streams)\n"
        f"  (:objects\n    {declared})\n"
        f"  (:init\n    {facts})\n"
        f"  (:goal (and\n    {goals})))\n"
    )
