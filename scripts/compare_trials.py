"""How two collections of the same stream differ, trial by trial (after a change to the primitives).

Usage: python scripts/compare_trials.py OLD NEW
OLD, NEW: a `*_trials.npz` file or a collector's work folder of chunk files. Trials are matched
by (task, attempt); those whose bins differ are counted apart. Prints one JSON object.
"""

from __future__ import annotations

import json
import sys
from collections import Counter
from pathlib import Path

import numpy as np

from hsgplan.data.motion_store import STATUSES


def _trials(path: Path) -> dict[tuple[int, int], tuple[tuple[int, int], int]]:
    files = sorted(path.glob("chunk-*.npz")) if path.is_dir() else [path]
    out = {}
    for f in files:
        d = np.load(f)
        for t, a, b, s in zip(d["task"], d["attempt"], d["bins"], d["status"], strict=True):
            out[int(t), int(a)] = (tuple(int(x) for x in b), int(s))
    return out


def main(argv: list[str]) -> int:
    if len(argv) != 2:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    old, new = (_trials(Path(a)) for a in argv)
    shared = old.keys() & new.keys()
    changed: Counter[str] = Counter()
    other_bins = 0
    for key in shared:
        (ob, os_), (nb, ns) = old[key], new[key]
        if ob != nb:
            other_bins += 1
        elif os_ != ns:
            changed[f"{STATUSES[os_]} -> {STATUSES[ns]}"] += 1
    same = len(shared) - other_bins - sum(changed.values())
    report = {"shared": len(shared), "same_outcome": same, "other_bins": other_bins}
    print(json.dumps(report | {"changed": dict(changed.most_common())}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
