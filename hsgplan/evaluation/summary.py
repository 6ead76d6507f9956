"""What a set of episodes sums to: success and subgoal completion per problem size, their
spread over repeats, the failure taxonomy and the time spent per level.

The failure taxonomy is the paper's (section 5.C), by what ended the episode: an **execution**
failure is an episode a failed primitive ended (under the paper's protocol the first failed
primitive does; in any protocol an object knocked over or off the table, or a motion generator
with nothing to propose; the kind is the fatal anomaly, or else the status of the primitive
that failed last), an **overstep** one that the step limit, or a planner with nothing reachable
to offer, ended. An overstep episode may have had primitives fail on its way (the recovering
protocol goes on after them): they are counted apart (`failed_primitives`,
`overstep_after_failures`), so that the classes stay the paper's.
"""

from __future__ import annotations

import statistics
from collections import Counter
from collections.abc import Mapping, Sequence

from hsgplan.evaluation.episode import EpisodeRecord
from hsgplan.evaluation.failures import Failure
from hsgplan.evaluation.intervals import goal_interval, training_goal_interval
from hsgplan.sim.outcome import DISTURB_RECORD, DISTURB_TOL, SEEN_DISTURB_TOL, Status

EXECUTION = "execution"
OVERSTEP = "overstep"
# the goal seen reached where it truly was not, an object never seen, or a step seen to fail
# where the goal truly held
PERCEPTION = "perception"
UNSAMPLED = "unsampled"  # no start scene: left out of every rate, counted apart
_ENDED_BY_PERCEPTION = {Failure.MISPERCEIVED, Failure.NEVER_SEEN, Failure.MISJUDGED}
# statuses of a primitive that failed in execution (an inapplicable one is the task level's)
FAILED_EXECUTION = frozenset(s.value for s in Status) - {Status.SUCCESS, Status.INVALID}
_ENDED_BY_EXECUTION = {Failure.KNOCKED_OVER, Failure.OFF_TABLE, Failure.NO_PARAMETERS}


def failed_steps(record: EpisodeRecord) -> list[str]:
    """The judge's statuses of the episode's primitives that did not succeed, in order (the
    same judge for every observer: `StepRecord.verdict`): those that failed in execution and
    those the world refused as inapplicable (`invalid`, nothing moved) alike, as the paper's
    protocol ends an episode at either."""
    return [s.verdict for s in record.steps if s.verdict != Status.SUCCESS]


def judged(record: EpisodeRecord) -> bool:
    """Whether the record holds the judge's verdicts (records made before it hold the robot's
    statuses alone)."""
    return any(s.truth for s in record.steps)


def class_of(failure: Failure) -> str:
    """The class of the taxonomy an episode ended by `failure` is counted in."""
    if failure == Failure.UNSAMPLED:
        return UNSAMPLED
    if failure in _ENDED_BY_PERCEPTION:
        return PERCEPTION
    if failure in _ENDED_BY_EXECUTION or failure == Failure.FAILED_PRIMITIVE:
        return EXECUTION
    return OVERSTEP


def failure_class(record: EpisodeRecord) -> tuple[str, str] | None:
    """(class, kind) of a failed episode, None for a success."""
    if record.success:
        return None
    kind = str(record.failure)
    # Records made before the judge: seeing through cameras, a step may be judged failed
    # where it succeeded; an episode it ended with every goal literal truly holding failed by
    # what the robot saw, not by what it did.
    legacy = not judged(record)
    if legacy and record.failure == Failure.FAILED_PRIMITIVE and record.subgoal_completion == 1:
        return PERCEPTION, str(Failure.MISJUDGED)
    if record.failure == Failure.FAILED_PRIMITIVE:
        # the step that failed the episode: the first the judge failed (in a record before
        # it, the last the robot saw fail, which ended it)
        failed = failed_steps(record)
        kind = (failed[-1] if legacy else failed[0]) if failed else kind
    elif record.failure == Failure.OVERSTEP:
        kind = "step limit"
    return class_of(Failure(record.failure)), kind


def _spread(values_by_repeat: dict[int, list[float]]) -> float | None:
    """Standard deviation over repeats of the per-repeat mean (None with a single repeat)."""
    means = [sum(v) / len(v) for v in values_by_repeat.values()]
    return statistics.pstdev(means) if len(means) > 1 else None


def _as_list(interval: tuple[float, float] | None) -> list[float] | None:
    return None if interval is None else list(interval)


def _by_goal(rs: Sequence[EpisodeRecord]) -> dict[str, list[float]]:
    goals: dict[str, list[float]] = {}
    for r in rs:
        goals.setdefault(r.goal, []).append(float(r.success))
    return goals


def size_summary(rs: Sequence[EpisodeRecord]) -> dict:
    by_repeat: dict[int, list[EpisodeRecord]] = {}
    for r in rs:
        by_repeat.setdefault(r.repeat, []).append(r)
    classed = [(r, c) for r in rs if (c := failure_class(r))]
    classes = [c for _, c in classed]
    return {
        "success_rate": sum(r.success for r in rs) / len(rs),
        "subgoal_completion": sum(r.subgoal_completion for r in rs) / len(rs),
        "episodes": len(rs),
        "repeats": len(by_repeat),
        "success_std": _spread({k: [r.success for r in v] for k, v in by_repeat.items()}),
        # a bootstrap over goals, each goal's episodes kept together (with several trainings
        # `summarize_trainings` draws trainings too)
        "success_ci": _as_list(goal_interval(_by_goal(rs))),  # as JSON gives it back
        "completion_std": _spread(
            {k: [r.subgoal_completion for r in v] for k, v in by_repeat.items()}
        ),
        "failures": dict(Counter(r.failure for r in rs if r.failure)),
        "failure_classes": {
            cls: dict(Counter(kind for c, kind in classes if c == cls))
            for cls in (EXECUTION, OVERSTEP, PERCEPTION)
        },
        # primitives that failed, in every episode; and overstep episodes that had some
        "failed_primitives": sum(len(failed_steps(r)) for r in rs),
        "overstep_after_failures": sum(
            1 for r, c in classed if c[0] == OVERSTEP and failed_steps(r)
        ),
        # primitives that truly moved an object besides their own (physics: a swept arm, a
        # carried object, a push), whatever their status
        "disturbing_steps": sum(1 for r in rs for s in r.steps if s.disturbed),
        # each object so moved, by primitive and the phase it moved in ("place:retreat")
        "disturbed_in": dict(
            sorted(
                Counter(
                    f"{s.action.split('(')[0]}:{d.phase or 'unknown'}"
                    for r in rs
                    for s in r.steps
                    for d in s.disturbed
                ).items()
            )
        ),
        # places whose object the retreating hand dragged on after letting it go (a drag is a
        # place's: a record of another primitive with one counts none)
        "dragged_steps": sum(
            1
            for r in rs
            for s in r.steps
            if s.action.startswith("place") and s.dragged > DISTURB_RECORD
        ),
        "still_seen_moved": still_seen_moved(rs),
        # steps the robot read otherwise than the judge (seeing through f_p; none under the
        # ground truth, whose reading is the judge's)
        "misread_steps": misread_steps(rs),
        "misbelieved": misbelieved(rs),
        # looks taken again before a primitive or the goal's end, seeing through f_p (`relook`)
        "relooks": sum(s.relooks for r in rs for s in r.steps) + sum(r.closing_relooks for r in rs),
        "median_steps": statistics.median(len(r.steps) for r in rs),
        "median_seconds": statistics.median(r.seconds for r in rs),
        "median_task_seconds": statistics.median(r.task_seconds for r in rs),
        # the motion level per episode: choosing parameters and executing them
        "median_motion_seconds": statistics.median(r.motion_seconds for r in rs),
    }


def still_seen_moved(rs: Sequence[EpisodeRecord]) -> dict:
    """How far the observer saw other objects move in the steps that truly moved none of them
    (none by DISTURB_RECORD): its spread between looks, which a step judged on the belief must
    tell from a disturbance (`sim.outcome.SEEN_DISTURB_TOL`). Zero under the ground truth."""
    moves = sorted(s.seen_moved for r in rs for s in r.steps if not s.disturbed)
    if not moves:
        return {"steps": 0}
    return {
        "steps": len(moves),
        "p99": moves[min(len(moves) - 1, int(0.99 * len(moves)))],
        "max": moves[-1],
        "beyond_2cm": sum(m > DISTURB_TOL for m in moves),
        "beyond_tolerance": sum(m > SEEN_DISTURB_TOL for m in moves),
    }


def misread_steps(rs: Sequence[EpisodeRecord]) -> dict:
    """Executed steps the robot saw succeed that the judge failed, and those it saw fail that
    the judge passed (records made before the judge count none)."""
    steps = [s for r in rs for s in r.steps if s.truth]
    ok = Status.SUCCESS
    return {
        "seen_ok_truly_failed": sum(1 for s in steps if s.status == ok and s.truth != ok),
        "seen_failed_truly_ok": sum(1 for s in steps if s.status != ok and s.truth == ok),
    }


def misbelieved(rs: Sequence[EpisodeRecord]) -> dict:
    """Steps planned on a belief that had an object they acted on off its true pose beyond
    f_p's targets (`sim.outcome.BELIEF_OFF`, `BELIEF_TURNED`), and the failed primitives among
    them: how much of what fails seeing through f_p is the belief's. The largest errors are
    over every step's objects. Zero under the ground truth."""
    errors = [(s, e) for r in rs for s in r.steps for e in s.misbelieved]
    off = {id(s): s for s, e in errors if e.beyond}
    return {
        "steps": len(off),
        "failed": sum(1 for s in off.values() if s.verdict in FAILED_EXECUTION),
        "max_off": max((e.off for _, e in errors), default=0.0),
        "max_turned": max((e.turned for _, e in errors), default=0.0),
    }


def summarize_trainings(runs: Mapping[int | None, Sequence[EpisodeRecord]]) -> dict:
    """`summarize` over every training's records (`{None: records}`: one training), each
    size's success rate with its interval over trainings and goals, repeats kept together
    (`intervals`),
    and with several trainings each one's rate."""
    summary = summarize([r for rs in runs.values() for r in rs])
    seeds = [s for s in runs if s is not None]
    summary["trainings"] = seeds
    for n, entry in summary["by_size"].items():
        if seeds:
            mine = {
                s: [r for r in runs[s] if str(r.size) == n and r.failure != Failure.UNSAMPLED]
                for s in seeds
            }
            entry["success_by_training"] = [_rate(mine[s]) for s in seeds]
            # the interval over trainings and goals, not over goals alone
            cells: dict[tuple[int, str], list[float]] = {}
            for s in seeds:
                for r in mine[s]:
                    cells.setdefault((s, r.goal), []).append(float(r.success))
            entry["success_ci"] = _as_list(training_goal_interval(cells))
    return summary


def _rate(rs: Sequence[EpisodeRecord]) -> float | None:
    return sum(r.success for r in rs) / len(rs) if rs else None


def summarize(records: Sequence[EpisodeRecord]) -> dict:
    """`{"by_size": {"2": {"success_rate", "subgoal_completion", "episodes", ...}, ...},
    "unsampled_scenes": {"12": 1, ...}}`. Episodes whose start scene could not be sampled are
    the world's, not the agent's: left out of every rate and counted apart, by size."""
    unsampled = Counter(str(r.size) for r in records if r.failure == Failure.UNSAMPLED)
    tried = [r for r in records if r.failure != Failure.UNSAMPLED]
    sizes = sorted({r.size for r in tried})
    by_size = {str(n): size_summary([r for r in tried if r.size == n]) for n in sizes}
    return {"by_size": by_size, "unsampled_scenes": dict(sorted(unsampled.items()))}
