"""How an episode can fail: one vocabulary for the simulated world and the symbolic loop."""

from __future__ import annotations

from enum import StrEnum


class Failure(StrEnum):
    OVERSTEP = "overstep"  # the step limit (`domain.world.MAX_STEPS`) came first
    NO_SUBGOAL = "no_subgoal"  # the task planner named no next action
    NO_PARAMETERS = "no_parameters"  # every parameter choice for the next action had failed
    FAILED_PRIMITIVE = "failed_primitive"  # the paper protocol: a primitive failed, which ends it
    KNOCKED_OVER = "knocked_over"  # simulated world: an object toppled
    OFF_TABLE = "off_table"  # simulated world: an object fell off the table
    MISPERCEIVED = "misperceived"  # the agent saw the goal reached where it truly was not
    NEVER_SEEN = "never_seen"  # the agent had to decide with no pose for an object of the goal
    # a primitive seen to fail ended the episode where the goal truly held: a record keeps
    # `failed_primitive`, and the taxonomy reads it so (`summary.failure_class`)
    MISJUDGED = "misjudged"
    # no start scene could be sampled for the goal: the world's limit, not the agent's; left
    # out of every rate and counted apart
    UNSAMPLED = "unsampled_scene"
