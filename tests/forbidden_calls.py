"""Catching calls into the hand-written rules while some code runs (tests only).

A profiler sees every Python call however it is reached, so a rule consulted through an
indirect import, a reference kept elsewhere or a re-export is caught as well as a direct one.
"""

import sys
from contextlib import contextmanager
from pathlib import Path

PACKAGE = Path(__import__("hsgplan").__file__).resolve().parent
RULES = (
    PACKAGE / "symbolic",
    PACKAGE / "domain" / "feasibility.py",
    PACKAGE / "planning" / "fast_downward.py",
)


def _is_rule(filename: str, rules) -> bool:
    path = Path(filename).resolve()
    return any(path == r or r in path.parents for r in rules)


@contextmanager
def rules_forbidden(calls: list[str], rules=RULES):
    """Every call into `rules` (folders or files) while inside, appended to `calls`."""

    def profile(frame, event, arg):
        if event == "call" and _is_rule(frame.f_code.co_filename, rules):
            calls.append(f"{frame.f_code.co_filename}:{frame.f_code.co_name}")

    sys.setprofile(profile)
    try:
        yield
    finally:
        sys.setprofile(None)
