"""What an agent sees the simulated world with, by name: `gt` (the simulator's poses), `rgb`
(f_p on the fixed cameras' images, `perception.observer.RgbObserver`) or `rgb-latest` (the same
with its `steady` rule off)."""

from __future__ import annotations

from pathlib import Path

from hsgplan.evaluation.config import check_observer
from hsgplan.sim.observer import GroundTruth, SceneObserver


def perception_folder(checkpoint: str | Path | None) -> Path:
    """f_p's checkpoint folder: `checkpoint`, or the shipped one."""
    from hsgplan.paths import PERCEPTION_CHECKPOINT

    return Path(checkpoint or PERCEPTION_CHECKPOINT)


def make_observer(name: str, checkpoint: str | Path | None = None) -> SceneObserver:
    """The observer `name`; for `rgb` its network is loaded (a missing or damaged checkpoint
    refused in one line)."""
    check_observer(name)
    if name == "gt":
        return GroundTruth()
    from hsgplan.perception.observer import RgbObserver

    return RgbObserver.load(perception_folder(checkpoint), steady=name == "rgb")
