"""Checks of what enters from outside: the bounds of every count a command takes, the values of
a configuration read from JSON, and text files read defensively. Each refusal is one
`InvalidInputError` line that names the value and the bound it breaks.

The bounds are generous for real use and small enough that no count can hang a command before
its progress bar shows (a billion goals would be drawn in memory for minutes first).
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import types
import typing
from pathlib import Path
from typing import Any

from hsgplan.domain.errors import InvalidInputError

MAX_SEED = 2**32 - 1  # numpy's and torch's seeders both take it
MAX_WORKERS = 256
MAX_GOALS = 100_000  # `goals --goals`, `eval --goals` and `eval task --goals` (per size)
MAX_REPEATS = 100
MAX_SAMPLES = 1_000_000  # `collect place/push --samples`
MAX_STATES = 1_000_000  # `collect reach --states`
MAX_TRIALS = 100_000  # `eval motion --trials` (per primitive)
MAX_TASKS = 100_000  # `bench push-reach --tasks`, `bench line-error --tasks`
MAX_EPISODES = 10_000  # `bench sim --episodes`
MAX_FAILURES = 1_000  # `report --failures`
MAX_TASKS_PER_CHUNK = 100_000
MAX_LAYOUTS = 10_000  # `scenes --layouts`
# The bounds of each count and seed a user gives, by what it counts: configurations declare
# their fields with them (`setting(0, **BOUNDS["seed"])`) and the command line's options take
# theirs from here (`cli.common.bounded_option`), so each bound is written once.
BOUNDS: dict[str, dict[str, int]] = {
    "seed": {"lo": 0, "hi": MAX_SEED},
    "workers": {"lo": 1, "hi": MAX_WORKERS},
    "goals": {"lo": 1, "hi": MAX_GOALS},
    "repeats": {"lo": 1, "hi": MAX_REPEATS},
    "samples": {"lo": 1, "hi": MAX_SAMPLES},
    "states": {"lo": 1, "hi": MAX_STATES},
    "trials": {"lo": 1, "hi": MAX_TRIALS},
    "tasks": {"lo": 1, "hi": MAX_TASKS},
    "scenes": {"lo": 1, "hi": MAX_TRIALS},
    "episodes": {"lo": 1, "hi": MAX_EPISODES},
    "failures": {"lo": 0, "hi": MAX_FAILURES},
    "layouts": {"lo": 1, "hi": MAX_LAYOUTS},
}
MAX_GOAL_FILE_GOALS = MAX_GOALS  # a goal file holds at most as many goals as --goals draws
MAX_GOAL_FILE_BYTES = 32 * 2**20  # 100,000 goals of 12 objects fit; parsed in about 10 s


def bounded(lo: float | None = None, hi: float | None = None, above: float | None = None) -> dict:
    """Field metadata for `check_fields`: `lo <= v <= hi`, or `v > above` (a learning rate)."""
    return {"lo": lo, "hi": hi, "above": above}


def setting(default: Any, **bounds: float | None) -> Any:
    """A dataclass field with a default and the bounds `check_fields` holds it to."""
    return dataclasses.field(default=default, metadata=bounded(**bounds))


def _allowed(hint) -> tuple[type, ...]:
    """The plain types a field's annotation admits (`int | None` -> int, NoneType)."""
    if isinstance(hint, types.UnionType) or typing.get_origin(hint) is typing.Union:
        return tuple(a for arg in typing.get_args(hint) for a in _allowed(arg))
    return (hint,)


def _check_value(name: str, value: Any, allowed: tuple[type, ...], meta) -> Any:
    if value is None and type(None) in allowed:
        return value
    if bool in allowed:
        if not isinstance(value, bool):
            raise InvalidInputError(f"{name} {value!r}: true or false")
        return value
    if str in allowed:
        if not isinstance(value, str):
            raise InvalidInputError(f"{name} {value!r}: need a string")
        return value
    if int in allowed and float not in allowed:
        if isinstance(value, bool) or not isinstance(value, int):
            raise InvalidInputError(f"{name} {value!r}: need an integer")
    elif float in allowed:
        value = check_number(name, value)
    return _within(name, value, meta.get("lo"), meta.get("hi"), meta.get("above"))


def check_number(name: str, value: Any, lo: float | None = None, hi: float | None = None) -> float:
    """A finite number within `lo` and `hi`, as a float; refused in one line that names it (the
    scene reader's numbers and a configuration's are refused in the same words)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise InvalidInputError(f"{name} {value!r}: need a number")
    if not math.isfinite(value):
        raise InvalidInputError(f"{name} {value!r}: need a finite number")
    return _within(name, float(value), lo, hi)


def _within(name: str, value: Any, lo=None, hi=None, above=None) -> Any:
    if lo is not None and value < lo:
        raise InvalidInputError(f"{name} {value!r}: must be at least {lo}")
    if hi is not None and value > hi:
        raise InvalidInputError(f"{name} {value!r}: must be at most {hi}")
    if above is not None and value <= above:
        raise InvalidInputError(f"{name} {value!r}: must be greater than {above}")
    return value


def check_fields(config) -> None:
    """Every field of a frozen dataclass against its annotation and its `setting` bounds;
    called by its `__post_init__`, so a configuration built from JSON or in code is checked
    alike. Integers given for float fields are stored as floats."""
    hints = typing.get_type_hints(type(config))
    for f in dataclasses.fields(config):
        value = _check_value(f.name, getattr(config, f.name), _allowed(hints[f.name]), f.metadata)
        object.__setattr__(config, f.name, value)


def from_settings(cls, settings: Any, what: str = "training setting"):
    """An instance of the dataclass `cls` from a JSON object; unknown keys and values of the
    wrong type or out of bounds are refused in one line."""
    if not isinstance(settings, dict):
        raise InvalidInputError(f"the {what}s must be one JSON object")
    unknown = set(settings) - {f.name for f in dataclasses.fields(cls)}
    if unknown:
        raise InvalidInputError(f"unknown {what}(s): {', '.join(sorted(map(str, unknown)))}")
    return cls(**settings)


def read_text(path: Path, what: str, max_bytes: int | None = None) -> str:
    """A UTF-8 text file (a byte-order mark is allowed) of at most `max_bytes`; anything else
    refused in one line, a file too large before it is read."""
    path = Path(path)
    if path.is_dir():
        raise InvalidInputError(f"{what} '{path}' is a folder, not a file")
    if path.exists() and not path.is_file():  # a FIFO or a device would block or never end
        raise InvalidInputError(f"{what} '{path}' is not a regular file")
    try:
        if max_bytes is not None and (size := path.stat().st_size) > max_bytes:
            raise InvalidInputError(
                f"{what} '{path}' is {size / 2**20:.1f} MiB; at most {max_bytes / 2**20:.0f} MiB"
            )
        data = path.read_bytes()
    except FileNotFoundError:
        raise InvalidInputError(f"{what} '{path}' does not exist") from None
    except OSError as e:
        raise InvalidInputError(f"{what} '{path}' cannot be read ({e.strerror})") from None
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise InvalidInputError(f"{what} '{path}' is not UTF-8 text") from None


def _no_constant(token: str):
    raise ValueError(f"{token} is not a JSON number")


def read_json(path: Path, what: str, shape: type = dict) -> Any:
    """A JSON file holding one value of type `shape`; strict JSON (no NaN or Infinity)."""
    text = read_text(path, what)
    try:
        value = json.loads(text, parse_constant=_no_constant)
    except RecursionError:
        raise InvalidInputError(f"{what} '{path}' is nested too deeply to be read") from None
    except ValueError as e:
        raise InvalidInputError(f"{what} '{path}' is not valid JSON ({e})") from None
    if not isinstance(value, shape):
        kind = {dict: "one JSON object", list: "a JSON list"}.get(shape, shape.__name__)
        raise InvalidInputError(f"{what} '{path}' must hold {kind}")
    return value


SYSTEM_TREES = ("/proc", "/sys", "/dev")


def resolve(path: Path) -> Path:
    """`path` made absolute with its links followed; a loop of links refused in one line."""
    try:
        return Path(path).resolve()
    except (RuntimeError, OSError) as e:  # 3.11 raises RuntimeError for a loop, 3.13 OSError
        raise InvalidInputError(f"'{path}' is a loop of symbolic links ({e})") from None


def check_output(path: Path, kind: str = "folder") -> None:
    """Refuse, before anything is written, a place output cannot go: a `kind` ("folder" or
    "file") where something else stands, a path under a file, a system tree, a folder we may
    not write in. A missing folder on the way is fine: it is made."""
    text = str(path)
    if not text.strip():
        raise InvalidInputError("an empty path; name a place for the output")
    path = Path(text).expanduser()
    resolved = resolve(path)
    if any(resolved == Path(t) or Path(t) in resolved.parents for t in SYSTEM_TREES):
        raise InvalidInputError(f"'{text}' is in a system tree, not a place for output")
    if path.exists():
        if kind == "folder" and not path.is_dir():
            raise InvalidInputError(f"'{text}' is a file, not a folder")
        if kind == "file" and not path.is_file():
            what = "a folder" if path.is_dir() else "not a regular file"
            raise InvalidInputError(f"'{text}' is {what}; name a file")
    start = resolved.parent if kind == "file" else resolved  # a file is replaced in its folder
    nearest = next(p for p in (start, *start.parents) if p.exists())
    if not nearest.is_dir():
        raise InvalidInputError(f"'{text}' is under '{nearest}', which is a file")
    if not os.access(nearest, os.W_OK):  # the path itself when it exists, else its folder
        raise InvalidInputError(f"'{text}': no permission to write in '{nearest}'")


ON, OFF = ("on", "true", "yes", "1"), ("off", "false", "no", "0")


def with_settings(rules, items, what: str):
    """The frozen dataclass `rules` with `NAME=VALUE` settings applied (`items`: a
    comma-separated text or a sequence): a bool field takes on or off, an int one a count, a
    float one a non-negative number. An unknown name or a bad value is refused in one line
    naming `what` (`perception rule`, `motion plan rule`)."""
    names = [f.name for f in dataclasses.fields(rules)]
    for item in (i.strip() for i in (items.split(",") if isinstance(items, str) else items)):
        if not item:
            continue
        name, sep, text = item.partition("=")
        name, text = name.strip(), text.strip().lower()
        if name not in names or not sep:
            raise InvalidInputError(
                f"{what} '{item}': write NAME=VALUE, NAME one of {', '.join(names)}"
            )
        kind = type(getattr(rules, name))
        if kind is bool:
            if text not in ON + OFF:
                raise InvalidInputError(f"{what} '{item}': {name} is on or off")
            value: Any = text in ON
        else:
            try:
                value = kind(text)
            except ValueError:
                value = math.nan
            if not math.isfinite(value) or value < 0:
                raise InvalidInputError(f"{what} '{item}': {name} is a number >= 0")
        rules = dataclasses.replace(rules, **{name: value})
    return rules


def changed_settings(rules) -> tuple[str, ...]:
    """The `NAME=VALUE` settings where the frozen dataclass `rules` differs from its defaults
    (what a run records of them)."""
    default = type(rules)()
    out = []
    for f in dataclasses.fields(rules):
        value = getattr(rules, f.name)
        if value != getattr(default, f.name):
            text = ("on" if value else "off") if isinstance(value, bool) else f"{value:g}"
            out.append(f"{f.name}={text}")
    return tuple(out)
