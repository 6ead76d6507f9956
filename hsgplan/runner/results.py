"""`hsgplan results`: every published table made again from the repository, in one command.

The plan (`configs/results/plan.toml`) lists the steps in order: collecting the data with
today's code, training every network three times, running every table on the test split. Each
step is one hsgplan command run in a child process; every such command resumes where it
stopped, so an interrupted pass, started again, goes on. A step that finished leaves
`runs/results/steps/NAME.json` (its command, the commit, its wall time) and is skipped while
its command is unchanged. A step with a `block` keeps its standard output as
`runs/results/blocks/NAME.md` beside `NAME.json`, the stamp `paste` writes under the block in
the README or docs: the command and the commit that made it.
"""

from __future__ import annotations

import datetime
import json
import os
import platform
import shlex
import subprocess
import sys
import time
import tomllib
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

from hsgplan.domain.errors import InvalidInputError
from hsgplan.files import write_atomically

PLAN = Path("configs/results/plan.toml")
OUT = Path("runs/results")


@dataclass(frozen=True)
class Step:
    name: str
    command: str  # an hsgplan command line, without `hsgplan`
    block: str | None = None  # the README / docs block its output becomes
    tags: tuple[str, ...] = ()
    ray: bool = False  # it takes --ray ADDRESS
    # a picture the command draws, and the page's copy of it: (made, shown)
    picture: tuple[str, str] | None = None

    def args(self, ray: str | None = None) -> list[str]:
        extra = ["--ray", ray] if ray and self.ray else []
        return [*shlex.split(self.command), *extra]


def read_plan(path: Path = PLAN) -> list[Step]:
    """The plan's steps; a malformed plan is refused in one line."""
    try:
        raw = tomllib.loads(Path(path).read_text())
    except (OSError, tomllib.TOMLDecodeError) as e:
        raise InvalidInputError(f"'{path}': not a readable plan ({e})") from None
    steps = []
    for i, entry in enumerate(raw.get("step", [])):
        try:
            steps.append(
                Step(
                    str(entry["name"]),
                    str(entry["command"]),
                    entry.get("block"),
                    tuple(entry.get("tags", ())),
                    bool(entry.get("ray", False)),
                    _picture(entry.get("picture")),
                )
            )
        except (KeyError, TypeError):
            raise InvalidInputError(f"'{path}': step {i + 1} needs a name and a command") from None
    names = [s.name for s in steps]
    if len(set(names)) != len(names):
        raise InvalidInputError(f"'{path}': every step needs a name of its own")
    return steps


def _picture(value) -> tuple[str, str] | None:
    if value is None:
        return None
    if not isinstance(value, list) or len(value) != 2 or not all(isinstance(v, str) for v in value):
        raise InvalidInputError(f"a step's picture {value!r}: write [made, shown]")
    return (value[0], value[1])


def copy_pictures(steps: list[Step], out: Path = OUT) -> list[str]:
    """Each finished step's picture copied to where its page shows it; the copies made."""
    copied = []
    for s in steps:
        if s.picture and finished(out, s) and Path(s.picture[0]).is_file():
            Path(s.picture[1]).parent.mkdir(parents=True, exist_ok=True)
            write_atomically(s.picture[1], Path(s.picture[0]).read_bytes())
            copied.append(s.picture[1])
    return copied


def writers(steps: list[Step], path: str) -> list[Step]:
    """The steps whose `--out` is `path` or a folder above it: those that make what is there."""
    made = []
    for s in steps:
        args = shlex.split(s.command)
        outs = [b for a, b in zip(args, args[1:], strict=False) if a == "--out"]
        if any(path == o or path.startswith(o.rstrip("/") + "/") for o in outs):
            made.append(s)
    return made


def chosen(steps: list[Step], only: Iterable[str] = (), skip: Iterable[str] = ()) -> list[Step]:
    """The steps named or tagged by `only` (all if none), less those with a tag or name in
    `skip`."""
    only, skip = set(only), set(skip)
    known = {s.name for s in steps} | {t for s in steps for t in s.tags}
    if unknown := sorted((only | skip) - known):
        raise InvalidInputError(f"no step or tag '{unknown[0]}' in the plan")
    return [
        s for s in steps if (not only or {s.name, *s.tags} & only) and not {s.name, *s.tags} & skip
    ]


def commit() -> str:
    """The commit the tree is at, `+` where it holds changes; `unknown` outside git."""
    try:
        head = subprocess.run(
            ["git", "rev-parse", "--short=12", "HEAD"], capture_output=True, text=True, check=True
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--untracked-files=no"],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return head + ("+" if dirty else "")


def _record_path(out: Path, step: Step) -> Path:
    return out / "steps" / f"{step.name}.json"


def finished(out: Path, step: Step) -> dict | None:
    """The record of the step's last finished pass, if its command was the same."""
    path = _record_path(out, step)
    try:
        made = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return made if made.get("command") == step.command else None


def run_step(
    step: Step, out: Path, ray: str | None = None, echo: Callable[[str], None] = print
) -> dict:
    """Run one step in a child process; its record. A failed step raises with its stderr's
    last line, and leaves no record."""
    start = time.perf_counter()
    at = commit()  # the code the child runs: the tree as it starts, not as it ends
    args = [sys.executable, "-m", "hsgplan.cli", *step.args(ray)]
    echo(f"{step.name}: hsgplan {shlex.join(step.args(ray))}")
    # stderr passes through (progress bars); stdout is the block
    result = subprocess.run(args, stdout=subprocess.PIPE, text=True, check=False)
    if result.returncode != 0:
        raise InvalidInputError(f"step '{step.name}' failed (exit code {result.returncode})")
    made = {
        "command": step.command,
        "commit": at,
        "date": str(datetime.date.today()),
        "machine": f"{platform.machine()}, {os.cpu_count()} cores",
        "wall_seconds": round(time.perf_counter() - start, 1),
    }
    (out / "steps").mkdir(parents=True, exist_ok=True)
    if step.block:
        (out / "blocks").mkdir(parents=True, exist_ok=True)
        write_atomically(out / "blocks" / f"{step.block}.md", result.stdout)
        write_atomically(out / "blocks" / f"{step.block}.json", json.dumps(made, indent=2) + "\n")
    write_atomically(_record_path(out, step), json.dumps(made, indent=2) + "\n")
    return made


def run_plan(
    steps: list[Step],
    out: Path = OUT,
    ray: str | None = None,
    echo: Callable[[str], None] = print,
) -> list[tuple[Step, dict]]:
    """Every step not yet finished with its command, in order; each step's record."""
    done = []
    for step in steps:
        made = finished(out, step)
        if made is None:
            made = run_step(step, out, ray, echo)
        else:
            echo(f"{step.name}: finished at {made['commit']} ({made['wall_seconds']:.0f} s)")
        done.append((step, made))
    return done


def stamp(made: dict) -> str:
    return (
        f"_Produced by `hsgplan results` (`hsgplan {made['command']}`) at commit "
        f"{made['commit']} on {made['date']} ({made['machine']})._"
    )


def paste(pages: Iterable[Path], out: Path = OUT, blocks: Iterable[str] | None = None) -> list[str]:
    """Put every saved block (those of `blocks`, else all) in its place on the pages, stamped
    with its command and commit; the names pasted. A block no page holds is refused."""
    import re

    texts = {p: p.read_text() for p in pages}
    folder = out / "blocks"
    names = sorted(p.stem for p in folder.glob("*.json")) if folder.is_dir() else []
    if blocks is not None:
        names = [n for n in names if n in set(blocks)]
    pasted = []
    for name in names:
        made = json.loads((folder / f"{name}.json").read_text())
        body = (folder / f"{name}.md").read_text().strip()
        pattern = re.compile(
            rf"(<!-- BEGIN {re.escape(name)} -->\n).*?(<!-- END {re.escape(name)} -->)", re.S
        )
        page = next((p for p, t in texts.items() if pattern.search(t)), None)
        if page is None:
            raise InvalidInputError(f"no page holds a block named '{name}'")
        block = f"{body}\n\n{stamp(made)}\n"
        texts[page] = pattern.sub(lambda m, b=block: m.group(1) + b + m.group(2), texts[page])
        pasted.append(name)
    for page, text in texts.items():
        if text != page.read_text():
            write_atomically(page, text)
    return pasted
