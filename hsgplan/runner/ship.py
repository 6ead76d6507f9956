"""`hsgplan results --ship`: the data and networks a finished pass made become the shipped ones.

The plan's `[[ship]]` entries name what is copied where: a collection's folder into `data/`,
the training of each configuration's own seed into `checkpoints/`. Working files stay behind
(a collection's `work/` chunks, its lock, its timing). Inside the copies' JSON files (training
configurations, label sources, collection settings) every path that names a shipped source is
rewritten to name where it now lives, so that `hsgplan train ... --config
checkpoints/task/train_config.json` reads the shipped data. The weights and their manifests
are copied as they are. A destination is replaced whole, through a copy beside it, so that an
interruption leaves either the old folder or the new one.
"""

from __future__ import annotations

import json
import shutil
import tomllib
from dataclasses import dataclass
from pathlib import Path

from hsgplan.domain.errors import InvalidInputError
from hsgplan.files import write_atomically

LEFT_BEHIND = ("work", "timing.json")  # a collection's chunks and its clock


@dataclass(frozen=True)
class Shipment:
    source: str
    destination: str


def read_shipments(plan: Path) -> list[Shipment]:
    try:
        raw = tomllib.loads(Path(plan).read_text())
    except (OSError, tomllib.TOMLDecodeError) as e:
        raise InvalidInputError(f"'{plan}': not a readable plan ({e})") from None
    try:
        return [Shipment(str(e["from"]), str(e["to"])) for e in raw.get("ship", [])]
    except (KeyError, TypeError):
        raise InvalidInputError(f"'{plan}': every [[ship]] needs a from and a to") from None


def _renamed(value, moves: list[Shipment]):
    """`value` with every shipped source path in its strings renamed to its destination (the
    longest source first: `runs/results/task` is not read inside `runs/results/task-staged`)."""
    if isinstance(value, str):
        for m in moves:
            if value == m.source or value.startswith(m.source + "/"):
                return m.destination + value[len(m.source) :]
            value = value.replace(f" {m.source} ", f" {m.destination} ")
            if value.endswith(f" {m.source}"):
                value = value[: -len(m.source)] + m.destination
        return value
    if isinstance(value, list):
        return [_renamed(v, moves) for v in value]
    if isinstance(value, dict):
        return {k: _renamed(v, moves) for k, v in value.items()}
    return value


def _copy(source: Path, into: Path) -> None:
    def ignore(folder: str, names: list[str]) -> list[str]:
        return [n for n in names if n.startswith(".") or n in LEFT_BEHIND]

    shutil.copytree(source, into, ignore=ignore)


def ship(
    shipments: list[Shipment], root: Path = Path("."), renames: list[Shipment] | None = None
) -> list[str]:
    """Copy every source over its destination under `root`; the destinations written. Paths
    inside the copies are renamed by `renames` (default: the `shipments`; a partial shipment
    renames by every entry of its plan, so that what it ships names where the rest will
    live)."""
    missing = [s.source for s in shipments if not (root / s.source).is_dir()]
    if missing:
        raise InvalidInputError(f"'{missing[0]}' is not there: finish the pass first")
    moves = sorted(renames or shipments, key=lambda s: len(s.source), reverse=True)
    written = []
    for s in shipments:
        target = root / s.destination
        fresh = target.with_name(target.name + ".shipping")
        shutil.rmtree(fresh, ignore_errors=True)
        _copy(root / s.source, fresh)
        for path in sorted(fresh.rglob("*.json")):
            if path.name == "manifest.json":
                continue  # the weights' own record, of bytes and hashes
            try:
                value = json.loads(path.read_text())
            except ValueError:
                continue
            renamed = _renamed(value, moves)
            if renamed != value:
                write_atomically(path, json.dumps(renamed, indent=2) + "\n")
        old = target.with_name(target.name + ".old")
        shutil.rmtree(old, ignore_errors=True)
        if target.exists():
            target.rename(old)
        target.parent.mkdir(parents=True, exist_ok=True)
        fresh.rename(target)
        shutil.rmtree(old, ignore_errors=True)
        written.append(s.destination)
    return written
