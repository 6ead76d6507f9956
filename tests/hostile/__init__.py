"""The hostile suite: bad input against every `hsgplan` command, each case expected to be
refused cleanly (one `error:` line, exit code 2, nothing written; `harness.py` says exactly
what counts). `test_hostile.py` runs every case under pytest (marked slow); `python -m
tests.hostile` runs them and tables the outcome by command (`--help` for its options).

The cases: `cases_input.py` (the command line and the files it names), `cases_state.py`
(damaged folders, one command's folder given to another, the shipped data), `cases_disk.py`
(large inputs, links, a full disk, damaged datasets and training progress).
"""

from __future__ import annotations

from tests.hostile.case import Case
from tests.hostile.cases_disk import disk_cases
from tests.hostile.cases_input import (
    config_cases,
    goal_file_cases,
    markup_cases,
    name_cases,
    number_cases,
    output_cases,
)
from tests.hostile.cases_state import cross_cases, data_loss_cases, state_cases

COMMANDS = (
    "plan",
    "goals",
    "demo",
    "eval",
    "report",
    "eval task",
    "eval reach",
    "eval motion",
    "bench sim",
    "bench symbolic",
    "bench task",
    "bench timing",
    "bench collect",
    "bench observe",
    "bench push-reach",
    "bench line-error",
    "bench push-settings",
    "bench compare-trials",
    "collect demos",
    "collect place",
    "collect push",
    "collect reach",
    "train task",
    "train motion",
    "collect images",
    "train perception",
    "eval perception",
)


def all_cases() -> list[Case]:
    cases = (
        output_cases()
        + number_cases()
        + config_cases()
        + goal_file_cases()
        + state_cases()
        + markup_cases()
        + name_cases()
        + cross_cases()
        + data_loss_cases()
        + disk_cases()
    )
    seen: dict[str, int] = {}
    for c in cases:  # ids unique: a repeated name gets a counter
        seen[c.id] = seen.get(c.id, 0) + 1
        if seen[c.id] > 1:
            c.name += f" #{seen[c.id]}"
    return cases
