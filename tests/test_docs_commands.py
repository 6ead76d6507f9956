"""Every command line the README and docs/ quote names a command and options the CLI takes:
a renamed option fails here before a reader meets it."""

import re
import shlex
from pathlib import Path

import pytest
import typer

from hsgplan.cli import app

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
# a quoted command: in a code block or an inline span, from `hsgplan` to the span's end
QUOTED = re.compile(r"(?:^|[`\s(])(?:\.venv/bin/)?hsgplan(?= )([^`\n]*)")


def _quoted_lines() -> list[tuple[str, str]]:
    out = []
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        text = re.sub(r"\\\n\s*", " ", text)  # a shell line continued
        for match in QUOTED.finditer(text):
            out.append((f"{page.name}: hsgplan{match.group(1)}", match.group(1)))
    return out


def _tokens(rest: str) -> list[str]:
    rest = rest.split("#")[0]  # a shell comment
    try:
        return shlex.split(rest)
    except ValueError:  # an unbalanced quote in prose: the words will do
        return rest.split()


def _commands(group, tokens: list[str]) -> tuple[list, list[str]]:
    """The commands a quoted line names (several where it writes `a|b`) and its other tokens
    (a group is told by its subcommands: Typer carries its own click)."""
    commands = [group]
    while tokens and all(hasattr(c, "commands") for c in commands):
        names = tokens[0].split("|")
        found = [c.commands[n] for c in commands for n in names if n in c.commands]
        if not found:
            break
        commands, tokens = found, tokens[1:]
    return commands, tokens


def _options(command) -> set[str]:
    return {o for p in command.params for o in (*p.opts, *p.secondary_opts)} | {"--help"}


LINES = _quoted_lines()


def test_the_pages_quote_commands():
    assert len(LINES) > 50  # the pattern still finds what the pages quote


@pytest.mark.parametrize("where,rest", LINES, ids=[w for w, _ in LINES])
def test_a_quoted_command_line_names_what_the_cli_takes(where, rest):
    root = typer.main.get_command(app)
    tokens = _tokens(rest)
    commands, tokens = _commands(root, tokens)
    if commands == [root]:
        name = next((t for t in tokens if not t.startswith("-")), "")
        assert not name or name in ("...", "COMMAND") or not name.isidentifier(), where
        return
    for token in tokens:
        for option in re.findall(r"(?<![\w-])--[a-z][a-z0-9-]*", token):
            assert any(option in _options(c) for c in commands), f"{where}: no {option}"


def test_every_choice_the_cli_offers_is_explained_in_the_cli_reference():
    from hsgplan.agents.registry import (
        AGENT_NAMES,
        MOTION_GENERATORS,
        SEARCH_BASELINES,
        TASK_PLANNERS,
    )

    page = (ROOT / "docs" / "cli.md").read_text(encoding="utf-8")
    agents = page.split("## Agents", 1)[1].split("\n## ", 1)[0]
    for name in (*AGENT_NAMES, *TASK_PLANNERS, *MOTION_GENERATORS, *SEARCH_BASELINES):
        assert f"`{name}`" in agents, name
