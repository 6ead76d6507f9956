"""Spellings the command line no longer takes, each refused in one line naming the new one (a
script written for the older vocabulary fails at once and says how to fix it)."""

from __future__ import annotations

from collections.abc import Sequence

# the command words once typed -> the words now
COMMANDS: dict[str, str] = {
    "eval-task": "eval task",
    "eval-reach": "eval reach",
    "eval-motion": "eval motion",
    "eval-perception": "eval perception",
}
# (command words, option) once typed -> the option now
OPTIONS: dict[tuple[str, str], str] = {
    ("plan", "--objects"): "--names",
    ("goals", "--count"): "--goals",
    ("collect images", "--count"): "--samples",
    ("eval reach", "--trials"): "--data",
    ("eval motion", "--checkpoints"): "--motion-checkpoints",
    ("eval perception", "--checkpoint"): "--perception-checkpoint",
    ("bench observe", "--checkpoint"): "--perception-checkpoint",
}
# (option, value) once typed -> the value now
VALUES: dict[tuple[str, str], str] = {("--agent", "paper"): "learned"}
EVAL_TOPICS = ("world", "task", "reach", "motion", "perception")


def hint(argv: Sequence[str]) -> str | None:
    """The line that refuses an older spelling in `argv` (the words after `hsgplan`), or None
    when nothing in it is an older spelling."""
    if not argv:
        return None
    first = argv[0]
    if first in COMMANDS:
        return f"'hsgplan {first}' is now 'hsgplan {COMMANDS[first]}'"
    if first == "eval" and len(argv) > 1 and argv[1].startswith("-") and argv[1] != "--help":
        return (
            "'hsgplan eval' takes what to evaluate first: 'hsgplan eval world "
            f"{' '.join(argv[1:3])} ...' runs the agent in the world (Table 1); "
            f"the others are {', '.join(EVAL_TOPICS[1:])}"
        )
    for (words, old), new in OPTIONS.items():
        command = words.split()
        if list(argv[: len(command)]) != command:
            continue
        if any(a == old or a.startswith(old + "=") for a in argv[len(command) :]):
            return f"'hsgplan {words} {old}' is now '{new}'"
    for (option, old), new in VALUES.items():
        pairs = zip(argv, argv[1:], strict=False)
        if f"{option}={old}" in argv or any(a == option and b == old for a, b in pairs):
            return f"'{option} {old}' is now '{option} {new}'"
    return None
