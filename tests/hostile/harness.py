"""Running a hostile case and judging what it did.

A clean refusal: exit code 2; stderr holds exactly one non-empty line and it starts with
`error:` (quoting the hostile text verbatim where the case says so); it finishes within the
timeout; nothing new appears in the case's folder and nothing the case put there changes.
Each case is classified as one of

    refused    the clean refusal above
    traceback  "Traceback" in stdout or stderr, or exit code 1 with a Python exception
    hang       still running at the timeout (killed with its process group)
    accepted   exit code 0, or files created or changed (bad input taken, data touched)
    usage-box  click/Typer's framed, multi-line usage error
    other      anything else (several stderr lines, input not quoted verbatim, ...)

A data-loss case (a default output folder that holds the shipped data) is clean, and counted
under "refused", when it is refused or when it exits 0 leaving the shipped copy unchanged.

Each case runs in a fresh folder (its cwd) with HSGPLAN_HOME pointing at a copy of the
repository's `checkpoints/` and `data/` made once per run (cases about the default output
folders get a copy of their own in their cwd, and HSGPLAN_HOME pointing there), PYTHONHASHSEED
unset, stdin closed, and a memory limit so that a huge count cannot take the machine down. The
command runs as a process of its own, forked by `launcher.py` (which has the imports done).
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import shutil
import stat
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

from tests.hostile.case import SHIPPED, Case

REPO = Path(__file__).resolve().parents[2]
KINDS = ("refused", "traceback", "hang", "accepted", "usage-box", "other")
TIMEOUT = 30.0  # seconds before a case counts as a hang
# A data-loss case runs its whole job when it rightly writes elsewhere (18 demonstrations, a
# collection of 4 samples): seconds alone, but minutes on a loaded machine.
JOB_TIMEOUT = TIMEOUT * 4


def timeout_of(case: Case) -> float:
    return JOB_TIMEOUT if case.keep else TIMEOUT


MEMORY = 4 * 2**30  # bytes of address space a case may take


class Launcher:
    """One `launcher.py` server: a process with the imports done that forks each command."""

    def __init__(self) -> None:
        env = {k: v for k, v in os.environ.items() if k != "PYTHONHASHSEED"}  # any hash seed
        self.proc = subprocess.Popen(
            [sys.executable, str(Path(__file__).with_name("launcher.py"))],
            env=env,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
            cwd=REPO,
        )
        if json.loads(self.proc.stdout.readline() or "{}").get("ready") is not True:
            raise RuntimeError("the hostile cases' launcher did not start")

    def run(self, **request) -> dict:
        self.proc.stdin.write(json.dumps(request) + "\n")
        self.proc.stdin.flush()
        return json.loads(self.proc.stdout.readline())

    def close(self) -> None:
        self.proc.stdin.close()
        self.proc.wait()


def shipped_copy(root: Path) -> Path:
    """A copy of the shipped checkpoints and data under `root`: the cases' HSGPLAN_HOME."""
    home = root / "home"
    for name in SHIPPED:
        shutil.copytree(REPO / name, home / name, symlinks=True)
    return home


@dataclass
class Result:
    case: Case
    kind: str
    gist: str
    code: int | None
    seconds: float
    stdout: str
    stderr: str
    touched: list[str]
    notes: list[str]


def snapshot(root: Path) -> dict[str, str]:
    """Every entry under `root`: a file by its content hash, a folder, a link, anything else
    (a FIFO is never opened)."""
    entries = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for name in dirnames + filenames:
            p = Path(dirpath) / name
            rel = str(p.relative_to(root))
            st = os.lstat(p)
            if stat.S_ISLNK(st.st_mode):
                entries[rel] = "link:" + os.readlink(p)
            elif stat.S_ISDIR(st.st_mode):
                entries[rel] = "dir"
            elif stat.S_ISREG(st.st_mode):
                h = hashlib.sha256()
                with open(p, "rb") as f:
                    for block in iter(lambda f=f: f.read(1 << 20), b""):
                        h.update(block)
                entries[rel] = h.hexdigest()
            else:
                entries[rel] = f"special:{stat.S_IFMT(st.st_mode)}"
    return entries


def quick_snapshot(root: Path) -> dict[str, tuple]:
    """Names, sizes and modification times: cheap enough to take around every case."""
    out = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for name in dirnames + filenames:
            p = Path(dirpath) / name
            st = os.lstat(p)
            out[str(p.relative_to(root))] = (st.st_mode, st.st_size, st.st_mtime_ns)
    return out


def diff(before: dict, after: dict) -> list[str]:
    changes = [f"created {k}" for k in sorted(after.keys() - before.keys())]
    changes += [f"removed {k}" for k in sorted(before.keys() - after.keys())]
    changes += [
        f"changed {k}" for k in sorted(before.keys() & after.keys()) if before[k] != after[k]
    ]
    return changes


def child_env(home: Path) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONHASHSEED", "COLUMNS", "LINES")}
    env["HSGPLAN_HOME"] = str(home)
    return env


def tail(path: Path, limit: int = 65536) -> str:
    with open(path, "rb") as f:
        f.seek(max(0, path.stat().st_size - limit))
        return f.read().decode("utf-8", "replace")


@dataclass(frozen=True)
class Outcome:
    code: int | None  # None: still running at the timeout, and killed
    stdout: str
    stderr: str

    @property
    def error_lines(self) -> list[str]:
        return [line for line in self.stderr.splitlines() if line.strip()]


def launch(
    launcher: Launcher, args: list[str], cwd: Path, home: Path, file_bytes: int | None = None
) -> Outcome:
    """One command line in `cwd` (its output kept beside it), as the cases run."""
    logs = Path(tempfile.mkdtemp(prefix="logs-", dir=cwd.parent))
    reply = launcher.run(
        args=[str(a) for a in args],
        cwd=str(cwd),
        env=child_env(home),
        mem_bytes=MEMORY,
        file_bytes=file_bytes,
        stdout=str(logs / "stdout"),
        stderr=str(logs / "stderr"),
        timeout=TIMEOUT * 4,
    )
    return Outcome(reply["code"], tail(logs / "stdout"), tail(logs / "stderr"))


def run_case(case: Case, launcher: Launcher, root: Path, home: Path) -> Result:
    """Set the case's folder up under `root`, run it, judge it, and remove the folder."""
    work = Path(tempfile.mkdtemp(prefix="case-", dir=root))
    try:
        return _run_case(case, launcher, work, home)
    finally:
        shutil.rmtree(work, ignore_errors=True)


def _run_case(case: Case, launcher: Launcher, work: Path, home: Path) -> Result:
    cwd = work / "cwd"
    cwd.mkdir()
    for step in case.setup:
        step(cwd, home)
    before = snapshot(cwd)
    home_before = quick_snapshot(home)
    reply = launcher.run(
        args=case.args,
        cwd=str(cwd),
        env=child_env(cwd if case.own_home else home),
        mem_bytes=MEMORY,
        file_bytes=case.file_bytes,
        stdout=str(work / "stdout"),
        stderr=str(work / "stderr"),
        timeout=timeout_of(case),
    )
    code = reply["code"]
    notes = ["left processes running after it exited (killed)"] if reply["lingering"] else []
    stdout, stderr = tail(work / "stdout"), tail(work / "stderr")
    touched = diff(before, snapshot(cwd))
    home_changes = diff(home_before, quick_snapshot(home))
    if home_changes:
        touched += [f"HSGPLAN_HOME: {c}" for c in home_changes]
        notes.append("the shared HSGPLAN_HOME changed while it ran")
    if case.keep:
        elsewhere = [
            t
            for t in touched
            if not t.startswith("HSGPLAN_HOME") and not _under(t.split(" ", 1)[1], case.keep)
        ]
        touched = [t for t in touched if t not in elsewhere]
        if elsewhere:
            notes.append("wrote outside the kept folders: " + "; ".join(elsewhere[:3]))
    kind, gist = classify(case, code, stdout, stderr, touched)
    if kind != "accepted" and touched:
        notes.append("also touched files: " + "; ".join(touched[:3]))
    return Result(case, kind, gist, code, reply["seconds"], stdout, stderr, touched, notes)


def _under(path: str, folders: tuple[str, ...]) -> bool:
    return any(path == f or path.startswith(f + "/") for f in folders)


def classify(case: Case, code, stdout: str, stderr: str, touched) -> tuple[str, str]:
    lines = [line for line in stderr.splitlines() if line.strip()]
    last = lines[-1].strip() if lines else ""
    if code is None:
        waited = f"still running after {timeout_of(case):g} s"
        return "hang", waited + (f"; stderr: {last}" if last else "")
    if "Traceback" in stderr or "Traceback" in stdout:
        return "traceback", _exception_line(stderr + "\n" + stdout) or last
    if code == 1 and (exc := _exception_line(stderr)):
        return "traceback", exc
    if code == 0 and case.keep and not touched:
        return "refused", f"exit 0 and {', '.join(case.keep)} unchanged (counted as clean)"
    if touched or code == 0:
        what = "; ".join(touched[:4]) + (
            f"; ... {len(touched) - 4} more" if len(touched) > 4 else ""
        )
        return "accepted", f"exit {code}" + (f"; {what}" if what else "")
    if any(line.lstrip().startswith(("Usage:", "╭", "│", "Try '")) for line in lines):
        return "usage-box", f"exit {code}; {len(lines)} stderr lines; {last}"
    if code == 2 and len(lines) == 1 and lines[0].startswith("error:"):
        if case.echo is not None and case.echo not in lines[0]:
            return "other", f"error line does not quote {case.echo!r} verbatim: {lines[0]}"
        return "refused", lines[0]
    first = lines[0].strip() if lines else "(no stderr)"
    more = f" ... {last}" if len(lines) > 1 else ""
    return "other", f"exit {code}; {len(lines)} stderr lines: {first}{more}"


EXCEPTION = re.compile(r"^\s*([A-Za-z_][\w.]*(Error|Exception|Warning|Exit|Interrupt))\b.*")


def _exception_line(text: str) -> str:
    found = [m.group(0).strip() for m in map(EXCEPTION.match, text.splitlines()) if m]
    return found[-1] if found else ""
