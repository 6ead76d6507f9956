"""`python -m tests.hostile`: every hostile case, tabled by command and outcome.

Usage: python -m tests.hostile [--jobs 2] [--only SUBSTRING] [--list] [--json] [--failures]

Output: a Markdown table of the outcomes per command, then totals (--json: one JSON object
with the counts and the failing cases; --failures: every failing case with its argv and the
first and last lines of its stderr). Exit code 0 when every case is refused cleanly, 1
otherwise.
"""

from __future__ import annotations

import argparse
import json
import shlex
import shutil
import sys
import tempfile
import threading
from concurrent.futures import ThreadPoolExecutor, as_completed
from pathlib import Path

from tests.hostile import COMMANDS, all_cases
from tests.hostile.case import Case
from tests.hostile.harness import KINDS, Launcher, Result, run_case, shipped_copy


def run_all(cases: list[Case], jobs: int) -> list[Result]:
    root = Path(tempfile.mkdtemp(prefix="hsgplan-hostile-"))
    home = shipped_copy(root)
    local = threading.local()
    launchers: list[Launcher] = []
    lock = threading.Lock()
    results: list[Result] = []

    def one(case: Case) -> Result:
        if not hasattr(local, "launcher"):
            local.launcher = Launcher()
            with lock:
                launchers.append(local.launcher)
        return run_case(case, local.launcher, root, home)

    try:
        with ThreadPoolExecutor(max_workers=jobs) as pool:
            for future in as_completed([pool.submit(one, c) for c in cases]):
                r = future.result()
                with lock:
                    results.append(r)
                    print(
                        f"[{len(results)}/{len(cases)}] {r.kind:<9} {r.seconds:5.1f}s {r.case.id}",
                        file=sys.stderr,
                        flush=True,
                    )
    finally:
        for launcher in launchers:
            launcher.close()
        shutil.rmtree(root, ignore_errors=True)
    order = {c.id: i for i, c in enumerate(cases)}
    return sorted(results, key=lambda r: order[r.case.id])


def counts_by_command(results: list[Result]) -> dict[str, dict[str, int]]:
    table = {}
    for command in [*COMMANDS, *sorted({r.case.command for r in results} - set(COMMANDS))]:
        rows = [r for r in results if r.case.command == command]
        if rows:
            table[command] = {"cases": len(rows)} | {
                k: sum(r.kind == k for r in rows) for k in KINDS
            }
    return table


def totals(table: dict[str, dict[str, int]]) -> dict[str, int]:
    return {k: sum(row[k] for row in table.values()) for k in ("cases", *KINDS)}


def markdown(results: list[Result]) -> str:
    table = counts_by_command(results)
    header = ("command", "cases", *KINDS)
    lines = ["| " + " | ".join(header) + " |", "|---|" + "---:|" * (len(header) - 1)]
    for command, row in [*table.items(), ("**total**", totals(table))]:
        lines.append("| " + " | ".join([command, *(str(row[k]) for k in header[1:])]) + " |")
    return "\n".join(lines)


def first_last(text: str) -> tuple[str, str]:
    lines = [line.rstrip() for line in text.splitlines() if line.strip()]
    return (lines[0], lines[-1]) if lines else ("", "")


def failure_json(r: Result) -> dict:
    first, last = first_last(r.stderr)
    return {
        "id": r.case.id,
        "command": r.case.command,
        "argv": ["hsgplan", *r.case.args],
        "kind": r.kind,
        "gist": r.gist,
        "exit_code": r.code,
        "seconds": round(r.seconds, 1),
        "stderr_first": first,
        "stderr_last": last,
        "touched": r.touched[:20],
        "notes": r.notes,
    }


def shell_line(args: list[str]) -> str:
    text = " ".join(shlex.quote(a) for a in ["hsgplan", *args])
    return text if len(text) <= 300 else text[:300] + f"... ({len(text)} characters)"


def print_failures(results: list[Result]) -> None:
    failing = [r for r in results if r.kind != "refused"]
    for kind in KINDS[1:]:
        group = [r for r in failing if r.kind == kind]
        if not group:
            continue
        print(f"\n## {kind} ({len(group)})\n")
        for r in group:
            first, last = first_last(r.stderr)
            print(f"- {r.case.id}\n  $ {shell_line(r.case.args)}\n  gist: {r.gist[:300]}")
            print(f"  exit {r.code}, {r.seconds:.1f} s")
            if first:
                print(f"  stderr first: {first[:200]}")
            if last and last != first:
                print(f"  stderr last:  {last[:200]}")
            for note in r.notes:
                print(f"  note: {note[:300]}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description="Every hostile case, tabled by outcome.")
    parser.add_argument("--jobs", type=int, default=2, help="cases run side by side")
    parser.add_argument("--only", help="run only cases whose id or argv holds this text")
    parser.add_argument("--list", action="store_true", help="list the cases and run nothing")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--failures", action="store_true", help="print every non-clean case")
    args = parser.parse_args(argv)
    cases = all_cases()
    if args.only:
        cases = [c for c in cases if args.only in c.id or args.only in " ".join(c.args)]
    if args.list:
        for c in cases:
            print(f"{c.id}\n    $ {shell_line(c.args)}")
        print(f"{len(cases)} cases")
        return 0
    if not cases:
        parser.error("no case matches --only")
    results = run_all(cases, max(1, args.jobs))
    clean = all(r.kind == "refused" for r in results)
    if args.json:
        table = counts_by_command(results)
        report = {
            "counts": table,
            "totals": totals(table),
            "failures": [failure_json(r) for r in results if r.kind != "refused"],
        }
        print(json.dumps(report, indent=2))
        return 0 if clean else 1
    print(markdown(results))
    if args.failures:
        print_failures(results)
    return 0 if clean else 1


if __name__ == "__main__":
    try:
        sys.exit(main())
    except BrokenPipeError:  # `| head`
        sys.stderr.close()
