"""The rules of f_p and its tracker that a run may switch off or set, by name.

Each is a choice made on measurements (configs/decisions.toml names the split and seeds it was
made on); a rule can be measured only if it can be taken away, so every such rule of the
estimator (`perception.estimator`, `fusion`, `apart`) and of the tracker
(`perception.observer`) reads its setting here. The defaults are the shipped rules.

A setting is written `NAME=VALUE` (`ray_gap=0.03`, `pixel_vote=off`); `PerceptionRules.parse`
reads a comma-separated list of them, and refuses an unknown name or a bad value in one line.
"""

from __future__ import annotations

from dataclasses import dataclass

from hsgplan.domain.checks import changed_settings, with_settings
from hsgplan.perception.fusion import NEAR_RAY, RAY_GAP
from hsgplan.perception.pnp import REFINE_ROUNDS

# A detection f_p named another type is only an object's if it is within this of where the
# object was last seen (within `observer.STILL` if a single view saw it).
TRACK_DISTANCE = 0.3  # m


@dataclass(frozen=True)
class PerceptionRules:
    """Args:
    cliques: views are matched in cliques, groups of most views first; off, the closest pairs
        of lines of sight are joined first (`fusion.grouped`).
    ray_gap: m between two views' lines of sight to one object's centroid (`fusion.RAY_GAP`).
    pixel_vote: a detection whose centroid another covers is named again by a vote of the
        pixels it keeps in sight (`PoseEstimator._retyped`); off, it keeps the name its
        members' centroid patches gave it.
    found_again_can: a lone view's can where several views saw a can of its type is that can
        found again, whatever its colour (`apart`).
    rest: unseen objects are supports when a look is made to rest, and an estimate left inside
        the table is dropped (`PoseEstimator.rest`).
    near_ray: m from a lone view's line of sight to the object's last pose within which its
        estimate is moved along the ray to that pose (`fusion.along_ray_near`); 0: never.
    track_distance: m from an object's last pose beyond which a detection of another type is
        never that object (`observer.assigned`).
    lone_still: a detection of another type that one view saw is an object's only within
        `observer.STILL` of its last pose (off: within `track_distance`, as several views').
    refine_rounds: rounds of the fit of the best view's pose to every view's keypoints
        (`pnp.estimate_pose`); 0: the best view's own fit.
    """

    cliques: bool = True
    ray_gap: float = RAY_GAP
    pixel_vote: bool = True
    found_again_can: bool = True
    rest: bool = True
    near_ray: float = NEAR_RAY
    track_distance: float = TRACK_DISTANCE
    lone_still: bool = True
    refine_rounds: int = REFINE_ROUNDS

    @staticmethod
    def parse(settings: str | tuple[str, ...] | list[str]) -> PerceptionRules:
        """The shipped rules with `settings` (`NAME=VALUE`, comma-separated or as a list)."""
        return with_settings(PerceptionRules(), settings, "perception rule")

    def changed(self) -> tuple[str, ...]:
        """The settings that differ from the shipped rules, as `NAME=VALUE` (what a run
        records)."""
        return changed_settings(self)


SHIPPED = PerceptionRules()
