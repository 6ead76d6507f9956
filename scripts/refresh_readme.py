"""Replace a results block with what a command prints, so no table is typed by hand.

Usage: python scripts/refresh_readme.py NAME [--saved FILE] -- hsgplan bench symbolic --markdown

The block is the text between `<!-- BEGIN NAME -->` and `<!-- END NAME -->`, in the README or in
one of the pages under docs/; it becomes the command's standard output followed by a line naming
the command, the commit it ran at, the date and the machine. With `--saved FILE`, the command is
not run again: FILE must be a table `hsgplan results` kept (`runs/results/blocks/NAME.md`, its
record beside it), and the stamp names the command and commit that made it.
"""

from __future__ import annotations

import datetime
import json
import os
import platform
import re
import shlex
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]


def main(argv: list[str]) -> int:
    saved = None
    if len(argv) > 2 and argv[1] == "--saved":
        saved, argv = Path(argv[2]), [argv[0], *argv[3:]]
    if len(argv) < 3 or argv[1] != "--":
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    name, command = argv[0], argv[2:]
    pattern = re.compile(
        rf"(<!-- BEGIN {re.escape(name)} -->\n).*?(<!-- END {re.escape(name)} -->)", re.S
    )
    page = next((p for p in PAGES if pattern.search(p.read_text())), None)
    if page is None:
        print(f"no page (README.md, docs/*.md) has a block named '{name}'", file=sys.stderr)
        return 2
    if saved is not None:
        record = saved.with_suffix(".json")
        if saved.suffix != ".md" or not record.is_file():
            print(f"'{saved}' is no table `hsgplan results` kept", file=sys.stderr)
            return 2
        made = json.loads(record.read_text())
        if shlex.split(made["command"]) != command[1:]:
            print(f"'{saved}' was made by `hsgplan {made['command']}`", file=sys.stderr)
            return 2
        output, at = saved.read_text(), made["commit"]
    else:
        result = subprocess.run(command, capture_output=True, text=True, check=False)
        if result.returncode != 0:
            print(result.stderr, file=sys.stderr)
            return result.returncode
        output, at = result.stdout, commit()
    stamp = (
        f"\n_Produced by `{shlex.join(command)}` at commit {at} on {datetime.date.today()} "
        f"({platform.machine()}, {os.cpu_count()} cores)._\n"
    )
    block = output.strip() + "\n" + stamp
    # read again: the page may have changed while the command ran (another refresh, an edit)
    text = page.read_text()
    page.write_text(pattern.sub(lambda m: m.group(1) + block + m.group(2), text))
    return 0


def commit() -> str:
    """The commit the tree is at, `+` where tracked files hold changes."""
    git = ["git", "-C", str(ROOT)]
    head = subprocess.run([*git, "rev-parse", "--short=12", "HEAD"], capture_output=True, text=True)
    dirty = subprocess.run(
        [*git, "status", "--porcelain", "--untracked-files=no"], capture_output=True, text=True
    )
    return head.stdout.strip() + ("+" if dirty.stdout.strip() else "") or "unknown"


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
