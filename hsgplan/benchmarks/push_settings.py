"""Push successes and CPU time per success under other push speeds and tries per staged scene:
`hsgplan bench push-settings`, the basis of PUSH_SUBSTEPS and ATTEMPTS_PER_TASK[push]
(`sim/primitives.py`, `data/motion_trials.py`, docs/decisions.md).

For each setting, runs push tasks of seed streams no data uses, one physics client per seed,
until each client has tried `trials` parameter pairs; client k in the kitchen, or in the k-th of
the worlds given, counted round. Time is process time: less sensitive to a
shared machine than wall time, still noisy by about 10%.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass

from hsgplan.data import motion_trials
from hsgplan.data.motion_tasks import draw_task
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.parameters import MotionPrimitive
from hsgplan.domain.scene import World
from hsgplan.sim import primitives
from hsgplan.sim.motion_plans import PUSH_STEP
from hsgplan.sim.scene import TIME_STEP, Scene

FIRST_SEED = 300  # seeds 300.., one a scene: no collection draws from them
PUSH = MotionPrimitive.PUSH
MAX_SUBSTEPS = 24  # 0.05 m/s, eight times slower than the shipped push
MAX_ATTEMPTS = 64  # tries a staged scene: generous, the collection's is 8


@dataclass(frozen=True)
class PushSetting:
    substeps: int  # physics steps per PUSH_STEP of push
    attempts: int  # pushes tried in a staged scene

    @property
    def speed(self) -> float:
        """The push's speed in m/s."""
        return PUSH_STEP / (self.substeps * TIME_STEP)


def parse_setting(text: str) -> PushSetting:
    """`SUBSTEPS:ATTEMPTS`, e.g. `3:8`, each within its bound."""
    substeps, _, attempts = text.strip().partition(":")
    try:
        setting = PushSetting(int(substeps), int(attempts))
    except ValueError:
        raise InvalidInputError(
            f"--setting '{text}': expected SUBSTEPS:ATTEMPTS, two whole numbers like 3:8"
        ) from None
    if not 1 <= setting.substeps <= MAX_SUBSTEPS:
        raise InvalidInputError(f"--setting '{text}': substeps must be 1 to {MAX_SUBSTEPS}")
    if not 1 <= setting.attempts <= MAX_ATTEMPTS:
        raise InvalidInputError(f"--setting '{text}': attempts must be 1 to {MAX_ATTEMPTS}")
    return setting


def tasks_per_scene(trials: int, setting: PushSetting) -> int:
    """The staged scenes a client runs to try `trials` pairs, `setting.attempts` a scene."""
    if setting.attempts > trials:
        raise InvalidInputError(
            f"--setting {setting.substeps}:{setting.attempts}: more attempts a scene than "
            f"--trials {trials}"
        )
    return trials // setting.attempts


@dataclass(frozen=True)
class PushSettingRow:
    substeps: int
    attempts: int
    push_m_per_s: float
    trials: int
    successes: int
    cpu_s_per_success: float

    def to_json(self) -> dict:
        return asdict(self)


def push_settings(
    scenes: int,
    trials: int,
    setting: PushSetting,
    worlds: Sequence[World],
    on_task: Callable[[], None] | None = None,
) -> PushSettingRow:
    tasks = tasks_per_scene(trials, setting)
    saved = primitives.PUSH_SUBSTEPS, motion_trials.ATTEMPTS_PER_TASK[PUSH]
    primitives.PUSH_SUBSTEPS, motion_trials.ATTEMPTS_PER_TASK[PUSH] = (
        setting.substeps,
        setting.attempts,
    )
    ran = successes = 0
    start = time.process_time()
    try:
        for seed in range(FIRST_SEED, FIRST_SEED + scenes):
            world = worlds[(seed - FIRST_SEED) % len(worlds)]
            with Scene((), seed=seed, world=world) as scene:
                for index in range(tasks):
                    got = motion_trials.run_task(scene, draw_task(PUSH, seed, index, world)) or []
                    ran += len(got)
                    successes += sum(t.ok for t in got)
                    if on_task:
                        on_task()
    finally:
        primitives.PUSH_SUBSTEPS, motion_trials.ATTEMPTS_PER_TASK[PUSH] = saved
    seconds = time.process_time() - start
    return PushSettingRow(
        setting.substeps,
        setting.attempts,
        round(setting.speed, 3),
        ran,
        successes,
        round(seconds / max(1, successes), 3),
    )
