"""One closed-loop episode: observe, decide, execute, until the goal holds or it cannot go on.

The agent acts on what the env's observer makes of the scene, and the episode ends on what it
senses: the goal seen reached, a toppled or fallen object seen, the step limit. It is judged
on the truth (the simulator's state) once, at the end, by one judge for every observer: each
executed step's verdict (`sim.outcome.judge`, kept by the env) joins its record, and a goal the
agent believes reached that does not truly hold is a failure (`MISPERCEIVED`). With the ground
truth as observer the robot's reading and the judge's are one.

Under the paper's protocol (`end_at_failure`) a primitive the robot sees fail (refused while
planning, or failed in execution) ends the episode, unless the goal holds all the same, and the
episode succeeds only where every executed step truly succeeded and the goal truly holds at
the end; a robot that stopped on a step it saw fail where the step truly succeeded, short of
its goal, failed by what it saw (`MISJUDGED`). Otherwise (recovering) a failed primitive costs
its step and the agent goes on from what it observes; the verdicts are counted all the same.

Every episode records its seed; the same seed, goal and agent give the same record (timings
aside).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, replace

from hsgplan.agents.base import Agent, Decision
from hsgplan.domain.errors import UnsampledSceneError
from hsgplan.domain.goals import Goal
from hsgplan.evaluation.failures import Failure
from hsgplan.scene_graph.symbol_mapping import AnomalyKind
from hsgplan.sim.env import KitchenStorageEnv, Observation, ResetOptions
from hsgplan.sim.outcome import BeliefError, Disturbance

_FATAL = {AnomalyKind.TOPPLED: Failure.KNOCKED_OVER, AnomalyKind.OFF_TABLE: Failure.OFF_TABLE}


@dataclass(frozen=True)
class StepRecord:
    step: int
    subgoal: str
    action: str
    params: str
    status: str
    detail: str
    task_seconds: float
    motion_seconds: float
    execution_seconds: float
    relooks: int = 0  # looks taken before the primitive, from out of the cameras' way
    # objects the primitive truly moved besides its own (the simulator's poses), and how far
    disturbed: tuple[Disturbance, ...] = ()
    # the largest move (m) its observer saw of an object besides its own, look before to after
    seen_moved: float = 0.0
    # how far (m) a place's object truly moved after the hand let it go (`sim.outcome.dragged`)
    dragged: float = 0.0
    # how far the belief it was planned on had its object and a place's target object from
    # the simulator's poses (zero under the ground truth)
    misbelieved: tuple[BeliefError, ...] = ()
    # the one judge's verdict on the step, on the simulator's state (`sim.outcome.judge`),
    # and why: under the ground truth the status itself; "" in records made before it
    truth: str = ""
    truth_detail: str = ""

    @property
    def verdict(self) -> str:
        """The judge's status of the step (the status, in records that hold none)."""
        return self.truth or self.status


@dataclass(frozen=True)
class EpisodeRecord:
    seed: int
    agent: str
    goal: str
    size: int
    success: bool
    subgoal_completion: float
    failure: str | None
    steps: tuple[StepRecord, ...]
    seconds: float
    repeat: int = 0  # which of a goal's repeated episodes (the protocol runs each several times)
    # The last decision's seconds when it gave nothing to execute (the agent found no subgoal
    # or no parameters): time spent like any other, that no step records.
    unexecuted_task_seconds: float = 0.0
    unexecuted_motion_seconds: float = 0.0
    observer: str = "gt"
    # Over every observation, objects the observer did not see (their poses carried over).
    unseen_objects: int = 0
    # Looks taken again (`relook`) before the agent believed its goal reached.
    closing_relooks: int = 0
    scene: str | None = None  # the scene file it ran in (None: the kitchen)

    @property
    def task_seconds(self) -> float:
        """The task level's seconds over the whole episode."""
        return sum(s.task_seconds for s in self.steps) + self.unexecuted_task_seconds

    @property
    def motion_seconds(self) -> float:
        """The motion level's seconds over the whole episode: choosing parameters, and
        executing them."""
        executed = sum(s.motion_seconds + s.execution_seconds for s in self.steps)
        return executed + self.unexecuted_motion_seconds

    def to_json(self) -> dict:
        d = asdict(self)
        if d["scene"] is None:  # as records were written before scenes were files
            del d["scene"]
        return d

    @staticmethod
    def from_json(d: dict) -> EpisodeRecord:
        return EpisodeRecord(**{**d, "steps": tuple(_step(s) for s in d["steps"])})


def _step(d: dict) -> StepRecord:
    moved = tuple(Disturbance(**m) for m in d.get("disturbed", ()))
    off = tuple(BeliefError(**m) for m in d.get("misbelieved", ()))
    return StepRecord(**{**d, "disturbed": moved, "misbelieved": off})


def unsampled(seed: int, agent: str, goal: Goal, observer: str) -> EpisodeRecord:
    """The record of an episode whose start scene could not be sampled: nothing was tried."""
    failure = str(Failure.UNSAMPLED)
    return EpisodeRecord(
        seed, agent, str(goal), goal.size, False, 0.0, failure, (), 0.0, observer=observer
    )


def judged_failure(
    seen: Failure | None, records: list[StepRecord], goal_holds: bool, end_at_failure: bool
) -> Failure | None:
    """What an episode failed by on the truth, given what ended it as the robot saw it
    (`seen`: None where it believed its goal reached), its steps with their verdicts and
    whether the goal truly holds. Under the paper's protocol a step that truly failed fails
    the episode, whatever the robot saw; a stop on a step seen to fail that truly succeeded,
    short of the goal, is the robot's misjudgment; its stop where the goal holds and every
    step truly succeeded is a success."""
    if end_at_failure and any(r.verdict != "success" for r in records):
        return Failure.FAILED_PRIMITIVE
    if seen == Failure.FAILED_PRIMITIVE:
        return None if goal_holds else Failure.MISJUDGED
    if seen is None and not goal_holds:
        return Failure.MISPERCEIVED
    return seen


def params_text(params) -> str:
    fields = ", ".join(f"{k}={v}" for k, v in asdict(params).items() if v is not None)
    return f"{type(params).__name__.removesuffix('Params').lower()}({fields})"


def run_episode(
    env: KitchenStorageEnv,
    agent: Agent,
    goal: Goal,
    seed: int,
    on_frame: Callable[[], None] | None = None,
    on_step: Callable[[StepRecord | None, Observation], None] | None = None,
    on_decide: Callable[[int, Decision], None] | None = None,
    end_at_failure: bool = False,
    others: tuple[str, ...] = (),
) -> EpisodeRecord:
    """Run one episode; `on_decide` sees each decision (with its step number) before it is
    executed, `on_step` the start (record None) and every step after it. With
    `end_at_failure` (the paper's protocol) the first failed primitive ends it. `others`:
    objects in the scene that the goal does not name (`ResetOptions`)."""
    start = time.perf_counter()
    try:
        _, info = env.reset(seed=seed, options=ResetOptions(goal, others=others))
    except UnsampledSceneError:
        return unsampled(seed, agent.name, goal, env.observer.name)
    obs: Observation = info["observation"]
    agent.reset(goal, seed)
    if on_step:
        on_step(None, obs)
    records: list[StepRecord] = []
    failure = None
    unexecuted = (0.0, 0.0)
    unseen = len(obs.unseen)
    closing = 0
    while True:
        if goal.satisfied_by(obs.symbols.state):
            # unsure of an object of the goal, the agent looks again before it believes it
            again = env.look_again(goal.objects)
            if again is None:
                break
            obs, closing = again, closing + 1
            unseen += len(obs.unseen)
            continue
        # what the robot sees: seeing through f_p, a fall its cameras missed goes on
        fatal = [a for a in obs.symbols.anomalies if a.kind in _FATAL]
        if fatal:
            failure = _FATAL[fatal[0].kind]
            break
        if env.steps >= env.max_steps:
            failure = Failure.OVERSTEP
            break
        aim = goal
        if obs.unknown:  # no view has found it yet: nothing to plan it with
            # `seek_unseen`: what is seen of the goal goes on, and may bring it into view
            aim = goal.without(obs.unknown) if env.rules.seek_unseen else None
            if aim is None or aim.satisfied_by(obs.symbols.state):
                failure = Failure.NEVER_SEEN
                break
        d = agent.decide(obs.scene_graph, obs.symbols.state, aim, feasible=env.lookahead)
        if d.params is None:
            failure = Failure.NO_SUBGOAL if d.action is None else Failure.NO_PARAMETERS
            unexecuted = (d.task_seconds, d.motion_seconds)
            break
        if on_decide:
            on_decide(len(records) + 1, d)
        _, _, _, _, info = env.step(d.params, on_frame)
        obs = info["observation"]
        unseen += len(obs.unseen)
        outcome = info["outcome"]
        agent.observe(d.params, outcome)
        record = StepRecord(
            len(records) + 1,
            str(d.subgoal or ""),
            str(d.action),
            params_text(d.params),
            outcome.status.value,
            outcome.detail,
            d.task_seconds,
            d.motion_seconds,
            outcome.seconds,
            outcome.relooks,
            info["disturbed"],
            round(info["seen_moved"], 4),
            info["dragged"],
            info["misbelieved"],
        )
        records.append(record)
        if on_step:
            on_step(record, obs)
        if end_at_failure and not outcome.ok and not goal.satisfied_by(obs.symbols.state):
            failure = Failure.FAILED_PRIMITIVE
            break
    # the truth, read once the robot is done: the judge's verdict on each step, the goal
    records = [
        replace(r, truth=v.status.value, truth_detail=v.detail)
        for r, v in zip(records, env.verdicts, strict=True)
    ]
    state = obs.true_symbols.state
    # Seeing through cameras, look-alike duplicates are named by the robot's first look, not
    # by the simulator's bodies: the goal is judged under every naming of them.
    readings = goal.readings() if env.believing else [goal]
    done = max(sum(state.holds(lit) for lit in g.literals) for g in readings)
    failure = judged_failure(failure, records, done == len(goal.literals), end_at_failure)
    env.close()
    return EpisodeRecord(
        seed,
        agent.name,
        str(goal),
        goal.size,
        failure is None,
        done / len(goal.literals),
        None if failure is None else str(failure),
        tuple(records),
        time.perf_counter() - start,
        unexecuted_task_seconds=unexecuted[0],
        unexecuted_motion_seconds=unexecuted[1],
        observer=env.observer.name,
        unseen_objects=unseen,
        closing_relooks=closing,
    )
