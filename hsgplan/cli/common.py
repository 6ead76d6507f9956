"""What every command shares: consoles, the bad-input guard, argument parsing, tables."""

from __future__ import annotations

import functools
import json
import sys
from enum import StrEnum
from pathlib import Path

import typer
from rich.console import Console
from rich.table import Table
from typer.core import TyperGroup

from hsgplan.agents.registry import AGENT_NAMES, MOTION_GENERATORS, TASK_PLANNERS
from hsgplan.domain.errors import InvalidInputError

out = Console()
err = Console(stderr=True)


class OneLineErrors(TyperGroup):
    """The top-level group: a usage error (an unknown choice, a malformed number) is one line on
    stderr and exit code 2, like every other refusal, instead of click's framed box."""

    def main(self, *args, standalone_mode: bool = True, **kwargs):
        try:
            code = super().main(*args, standalone_mode=False, **kwargs)
        except typer.TyperException as e:  # click's exceptions, as typer ships them
            if type(e).__name__ == "NoArgsIsHelpError":
                e.show()
            else:
                message = " ".join(e.format_message().split())
                err.print(f"[bold red]error:[/] {message}", highlight=False, soft_wrap=True)
            code = e.exit_code
        except typer.Abort:
            err.print("aborted")
            code = 1
        code = code if isinstance(code, int) else 0
        if standalone_mode:
            sys.exit(code)
        return code


def refuses_bad_input(fn):
    """Bad input becomes one line on stderr and exit code 2, never a traceback."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        try:
            return fn(*args, **kwargs)
        except InvalidInputError as e:
            err.print(f"[bold red]error:[/] {e}", highlight=False, markup=True, soft_wrap=True)
            raise typer.Exit(2) from None
        except KeyboardInterrupt:
            err.print("interrupted")
            raise typer.Exit(130) from None

    return wrapper


def choice(what: str, names) -> type[StrEnum]:
    """Names offered as choices, listed by `--help` and checked by the parser (its `.value` is
    the name)."""
    return StrEnum(what, {name: name for name in names})


AgentName = choice("AgentName", AGENT_NAMES)
PlannerName = choice("PlannerName", TASK_PLANNERS)
MotionName = choice("MotionName", MOTION_GENERATORS)


def read_config(path: Path | None) -> dict:
    """The settings in a `--config` JSON file (none without a file), refused in one line."""
    if path is None:
        return {}
    try:
        settings = json.loads(path.read_text())
    except FileNotFoundError:
        raise InvalidInputError(f"--config '{path}' does not exist") from None
    except json.JSONDecodeError:
        raise InvalidInputError(f"--config '{path}' is not valid JSON") from None
    if not isinstance(settings, dict):
        raise InvalidInputError(f"--config '{path}' must hold one JSON object")
    return settings


def parse_sizes(text: str) -> list[int]:
    """`2-6`, `2,4,6` or `3` as a list of sizes."""
    sizes: list[int] = []
    try:
        for part in text.split(","):
            lo, _, hi = part.strip().partition("-")
            sizes += list(range(int(lo), int(hi or lo) + 1))
    except ValueError:
        raise InvalidInputError(
            f"--sizes '{text}': expected a range like 2-6 or a list like 2,4,6"
        ) from None
    from hsgplan.symbolic.generator import check_size

    if not sizes:
        raise InvalidInputError(f"--sizes '{text}' names no size")
    for n in sizes:
        check_size(n)
    return sizes


def print_table(title: str, header: tuple[str, ...], rows: list[tuple[str, ...]], markdown: bool):
    """A Rich table on the terminal, or a Markdown table that the README takes verbatim."""
    if markdown:
        print(f"{title}\n")
        print("| " + " | ".join(header) + " |")
        print("|" + "---:|" * len(header))
        for row in rows:
            print("| " + " | ".join(row) + " |")
        return
    table = Table(title=title)
    for col in header:
        table.add_column(col, justify="right")
    for row in rows:
        table.add_row(*row)
    out.print(table)
