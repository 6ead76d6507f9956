"""A task planner's checkpoint made of two others' networks: one's f_preimage (and forward
baseline), the other's f_reach. This is how the f_preimage x f_reach grid, and the task ladder's
rows that change f_reach alone, are evaluated without training anything again. Each network is
copied whole (weights, configuration, manifest, label counts) and verified; `combined.json`
names where each came from and the fingerprint of what was copied.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

from hsgplan.checkpoint import fingerprint, verify
from hsgplan.domain.errors import InvalidInputError
from hsgplan.files import write_atomically
from hsgplan.paths import shipped

COMBINED = "combined.json"
# the networks taken from the f_preimage checkpoint; f_reach comes from the other
FROM_PREIMAGE = ("preimage", "forward")


def combine(preimage: Path, reach: Path, out: Path) -> dict:
    """Write `out` from `preimage`'s f_preimage and forward baseline and `reach`'s f_reach;
    returns what `combined.json` holds. A missing or damaged network, or an `out` that holds
    anything but an earlier combination, is refused in one line, before anything is written."""
    sources = {name: shipped(preimage) / name for name in FROM_PREIMAGE}
    sources["reach"] = shipped(reach) / "reach"
    for name, folder in sources.items():
        if name != "forward":  # the forward baseline is copied where there is one
            verify(folder, f"f_{name}")
    if out.exists() and (
        not out.is_dir() or (any(out.iterdir()) and not (out / COMBINED).exists())
    ):
        raise InvalidInputError(f"'{out}' holds something else; use another --out")
    out.mkdir(parents=True, exist_ok=True)
    for name, folder in sources.items():
        if not folder.is_dir():
            continue
        target = out / name
        shutil.rmtree(target, ignore_errors=True)
        shutil.copytree(folder, target, ignore=shutil.ignore_patterns(".*", "progress.*"))
    record = {
        "preimage": str(preimage),
        "reach": str(reach),
        "fingerprint": fingerprint([out / n for n in sources if (out / n).is_dir()]),
    }
    write_atomically(out / COMBINED, json.dumps(record, indent=2) + "\n")
    return record
