"""The rules of the hand-written motion planner (`sim.motion_plans`) that a run may set by name.

Each was chosen on a measurement (configs/decisions.toml); to measure one against its absence
a run sets it (`eval world --plan-rules descent_points=0`), and the episode's scene plans by
it. The defaults are the shipped rules.
"""

from __future__ import annotations

from dataclasses import dataclass

from hsgplan.domain.checks import changed_settings, with_settings

# Poses solved between a final approach's ends: the hand then strays under 1 mm from the line.
DESCENT_POINTS = 3


@dataclass(frozen=True)
class PlanRules:
    """Args:
    descent_points: poses solved between the ends of a grasp's or a place's final approach,
        each from the last, so that the hand moves on a straight line (0: a straight line in
        joint space, which bows the hand sideways).
    descent_branch: the joints at the object must stay on the descent's branch (a solution
        on another is refused like a colliding one); off, any solution is taken.
    """

    descent_points: int = DESCENT_POINTS
    descent_branch: bool = True

    @staticmethod
    def parse(settings: str | tuple[str, ...] | list[str]) -> PlanRules:
        return with_settings(PlanRules(), settings, "motion plan rule")

    def changed(self) -> tuple[str, ...]:
        return changed_settings(self)


SHIPPED = PlanRules()
