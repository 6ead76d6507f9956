"""The names a results table prints, each said once: a primitive's statuses and the ends of an
episode, read from their enums, so the reference (`docs/failures.md`, made by `python -m
hsgplan.evaluation.glossary`) cannot drift from the code. A test holds the page to it."""

from __future__ import annotations

from hsgplan.evaluation.failures import Failure
from hsgplan.evaluation.summary import class_of
from hsgplan.sim.outcome import (
    BELIEF_OFF,
    BELIEF_TURNED,
    DISTURB_TOL,
    SEEN_DISTURB_TOL,
    Status,
)

STATUSES = {
    Status.SUCCESS: "the primitive did what it was for.",
    Status.INVALID: "its parameters cannot apply to the scene as it is (a place with nothing "
    "in the hand); nothing moved.",
    Status.NO_IK: "no collision-free arm configuration for a pose it needs (a shelf cell so "
    "crowded that no grasp of the can fits); refused before the arm moves.",
    Status.NO_PATH: "the motion planner found no path to it, or a push line left the arm's "
    "reach; refused before the arm moves.",
    Status.DROPPED: "after a pick the object did not rise with the hand (it closed where the "
    "object was believed to be, or the object slipped out), or was lost on the way.",
    Status.KNOCKED_OVER: "an object toppled (a can put down on a box's edge).",
    Status.OFF_TABLE: "an object fell off the table.",
    Status.DISTURBED: f"another object moved: more than {100 * DISTURB_TOL:.0f} cm in the "
    "simulator, or its place changed (the judge's); the robot seeing through f_p reads it as "
    "seen in another place, or, seen by several views both times, more than "
    f"{100 * SEEN_DISTURB_TOL:.0f} cm away.",
    Status.EFFECT_NOT_REACHED: "the primitive ran but its intended literal does not hold (a "
    "push too short to bring the can into the shelf).",
    Status.BLOCKS_PICK: "motion data only: the place reached its effect but left an object "
    "there that can no longer be taken up.",
    Status.BLOCKED: "the arm was stopped short by what it met, and the effect does not hold.",
}

ENDINGS = {
    Failure.OVERSTEP: "the step limit came first (tables show it as `step limit`).",
    Failure.NO_SUBGOAL: "the task planner found nothing reachable to do next.",
    Failure.NO_PARAMETERS: "every choice of parameters for the next action had failed "
    "(recovering protocol).",
    Failure.FAILED_PRIMITIVE: "paper protocol: a primitive truly failed (the judge's verdict, "
    "for every observer), which fails the episode; tables show that verdict (`no_ik 4`: four "
    "episodes failed by a refused arm configuration).",
    Failure.KNOCKED_OVER: "an object toppled.",
    Failure.OFF_TABLE: "an object fell off the table.",
    Failure.MISPERCEIVED: "the robot saw its goal reached where it truly was not.",
    Failure.NEVER_SEEN: "an object of the goal that no view had found when the robot had to "
    "decide on it (with `seek_unseen`, once the part of the goal it had seen held).",
    Failure.MISJUDGED: "paper protocol, seeing through f_p: the robot stopped on a primitive "
    "it saw fail that truly succeeded, short of its goal (records made before the one judge: "
    "`failed_primitive` where the goal truly held).",
    Failure.UNSAMPLED: "no start scene could be sampled for the goal's objects (the world's "
    "limit, not the agent's failure): nothing was tried; left out of every rate and counted "
    "apart (`unsampled`).",
}


# The failure table's columns (`evaluation.table1.failure_table`), beyond method and objects
COLUMNS = {
    "episodes": "run at that size.",
    "failed": "failed episodes, every class.",
    "execution": "ended by a primitive: the fatal anomaly or its status.",
    "overstep": "ended by the step limit, or nothing reachable to do.",
    "perception": "f_p: the goal seen reached where it was not, an object no view found, or a "
    "stop on a success seen to fail.",
    "failed primitives": "primitives that truly failed, in every episode.",
    "overstep after failures": "overstep episodes that had failed primitives.",
    "disturbing steps": "primitives that moved another object than their own.",
    "relooks": "f_p: looks taken again before a primitive.",
    "belief off": "f_p: failed primitives planned on a belief more than "
    f"{BELIEF_OFF * 100:.0f} cm or {BELIEF_TURNED:.0f}° off an object they acted on.",
    "misread": "f_p: steps seen to succeed that truly failed / seen to fail that truly succeeded.",
    "unsampled": "goals with no start scene, left out of the columns before.",
}


def glossary() -> str:
    """The three tables of `docs/failures.md`, in Markdown."""
    lines = [
        "A primitive's status (each step's `status` in `episodes.jsonl`, as the robot read it, "
        "and `truth`, the judge's verdict on the simulator's state):",
        "",
    ]
    lines += ["| status | meaning |", "|---|---|"]
    lines += [f"| `{s}` | {STATUSES[s]} |" for s in Status]
    lines += ["", "What ended a failed episode (its `failure`), and the class tables count it in:"]
    lines += ["", "| failure | class | meaning |", "|---|---|---|"]
    lines += [f"| `{f}` | {class_of(f)} | {ENDINGS[f]} |" for f in Failure]
    lines += ["", "What each column of a failure table counts:", ""]
    lines += ["| column | counts |", "|---|---|"]
    lines += [f"| {c} | {meaning} |" for c, meaning in COLUMNS.items()]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    print(glossary(), end="")
