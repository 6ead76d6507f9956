"""Where every training label of a task-planner checkpoint comes from, as a Markdown table.

Usage: python scripts/label_sources.py CHECKPOINT [CHECKPOINT ...]

Reads the `labels.json` that `hsgplan train task` writes beside each network (examples,
supervised slots and slots per class, by source). For f_reach the classes are no / yes; for
f_preimage and the forward baseline don't care / true / false.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

CLASSES = {"reach": ("no", "yes"), "preimage": ("don't care", "true", "false")}
CLASSES["forward"] = CLASSES["preimage"]


def rows(checkpoint: Path) -> list[str]:
    out = []
    for network in ("preimage", "reach", "forward"):
        path = checkpoint / network / "labels.json"
        if not path.is_file():
            raise SystemExit(f"'{path}' is missing: train the checkpoint with `hsgplan train task`")
        for source, c in json.loads(path.read_text()).items():
            classes = ", ".join(
                f"{name} {n:,}" for name, n in zip(CLASSES[network], c["by_class"], strict=False)
            )
            out.append(
                f"| {checkpoint.name} | {network} | {source} | {c['examples']:,} "
                f"| {c['labels']:,} | {classes} |"
            )
    return out


def main(argv: list[str]) -> int:
    if not argv:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    print("| checkpoint | network | labels from | examples | labels | by class |")
    print("|---|---|---|---:|---:|---|")
    for arg in argv:
        print("\n".join(rows(Path(arg))))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
