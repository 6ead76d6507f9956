"""What an agent sees the simulated world with, by name: `gt` (the simulator's poses), `rgb`
(f_p on the fixed cameras' images, `perception.observer.RgbObserver`), `rgb-latest` (the same
with its `steady` rule off) or `rgb-keypoint-yaw` (the same with its boxes' yaws as their
keypoints say, unchecked by their silhouettes: `perception.silhouette`)."""

from __future__ import annotations

from pathlib import Path

from hsgplan.evaluation.config import check_observer
from hsgplan.paths import perception_folder
from hsgplan.sim.observer import GroundTruth, SceneObserver


def make_observer(
    name: str, checkpoint: str | Path | None = None, rules: tuple[str, ...] = ()
) -> SceneObserver:
    """The observer `name`; for `rgb` its network is loaded (a missing or damaged checkpoint
    refused in one line), its rules set by `rules` (`perception.rules`, NAME=VALUE)."""
    check_observer(name)
    if name == "gt":
        return GroundTruth()
    from hsgplan.perception.observer import RgbObserver
    from hsgplan.perception.rules import PerceptionRules

    folder = perception_folder(checkpoint)
    steady, silhouette = name != "rgb-latest", name != "rgb-keypoint-yaw"
    return RgbObserver.load(folder, name, steady, silhouette, PerceptionRules.parse(rules))
