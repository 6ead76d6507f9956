"""The record of choices (`configs/decisions.toml`): every rule, threshold, hyperparameter, data
recipe and camera choice, what chose it, on which split and seeds, and where it stands.

A choice is made on the tune split (`chosen_on = "tune"`: tuning seeds), on training data alone
(`"train"`: held-out training scenes), or was made on a seed that also reports numbers
(`"reporting"`), which it may not stay: such a row says whether the tune split has since kept,
changed or dropped it, or that it is still to be chosen again. No row may cite a test seed: a
run seed of the test split or an episode seed a test-split run draws (`hsgplan splits
decisions` exits 1, and a test fails).
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from pathlib import Path

from hsgplan.domain.errors import InvalidInputError
from hsgplan.evaluation.seeds import is_tuning
from hsgplan.evaluation.splits import TEST

RECORD = Path("configs/decisions.toml")
CHOSEN_ON = ("tune", "train", "reporting")
# what a row chosen on a reporting seed may say of itself
REPORTING_STATUS = ("to choose again on tune", "kept on tune", "changed on tune", "dropped on tune")
_KEYS = ("name", "what", "where", "chosen_on", "seeds", "measurement", "status")


@dataclass(frozen=True)
class Decision:
    name: str
    what: str
    where: str
    chosen_on: str
    seeds: tuple[int, ...]
    measurement: str
    status: str

    @property
    def open(self) -> bool:
        """Made on a reporting seed and not yet made again on the tune split."""
        return self.chosen_on == "reporting" and self.status.startswith(REPORTING_STATUS[0])


def read_decisions(path: Path = RECORD) -> list[Decision]:
    """The record's rows; a malformed row is refused in one line."""
    try:
        rows = tomllib.loads(Path(path).read_text()).get("decision", [])
    except (OSError, tomllib.TOMLDecodeError) as e:
        raise InvalidInputError(f"'{path}': not a readable record of decisions ({e})") from None
    decisions = []
    for i, row in enumerate(rows):
        if missing := [k for k in _KEYS if k not in row]:
            raise InvalidInputError(f"'{path}': decision {i + 1} has no {missing[0]}")
        d = Decision(**{k: row[k] for k in _KEYS} | {"seeds": tuple(int(s) for s in row["seeds"])})
        if d.chosen_on not in CHOSEN_ON:
            raise InvalidInputError(
                f"'{path}': {d.name}: chosen_on '{d.chosen_on}', one of {', '.join(CHOSEN_ON)}"
            )
        if d.chosen_on == "reporting" and not d.status.startswith(REPORTING_STATUS):
            raise InvalidInputError(
                f"'{path}': {d.name} was chosen on a reporting seed; its status must begin "
                f"with one of: {'; '.join(REPORTING_STATUS)}"
            )
        decisions.append(d)
    names = [d.name for d in decisions]
    if len(set(names)) != len(names):
        dup = next(n for n in names if names.count(n) > 1)
        raise InvalidInputError(f"'{path}': '{dup}' is recorded twice")
    return decisions


def cited_test_seeds(d: Decision, test_episode_seeds: frozenset[int] = frozenset()) -> list[int]:
    """The test seeds a row cites: a run seed of the test split, or an episode seed of one."""
    return [s for s in d.seeds if s in TEST.seeds or s in test_episode_seeds]


def misfiled(d: Decision) -> list[int]:
    """Seeds of a row said to be chosen on tune that are no tuning seeds."""
    if d.chosen_on != "tune":
        return []
    return [s for s in d.seeds if not is_tuning(s, perception=True)]


def rows(decisions: list[Decision]) -> list[tuple[str, ...]]:
    return [
        (
            f"`{d.name}`",
            d.what,
            f"{d.chosen_on} ({', '.join(map(str, d.seeds)) or 'no seed'})" + _standing(d),
            d.measurement,
        )
        for d in decisions
    ]


def _standing(d: Decision) -> str:
    """Where a choice stands, said only where its split does not say it already."""
    return "" if d.status == f"chosen on {d.chosen_on}" else f"; {d.status}"


HEADER = ("choice", "what", "chosen on (seeds); where it stands", "by")


def markdown(decisions: list[Decision]) -> str:
    """The record as a Markdown list, a choice an item: its cells are sentences, which a table
    squeezes into narrow columns."""
    return "\n".join(
        f"- {name}: {what}. {chosen}. By {by}" for name, what, chosen, by in rows(decisions)
    )
