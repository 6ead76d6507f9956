"""The recovery rules: what the agent does after a failure, beyond the paper.

The paper's agent has none: a primitive that fails ends its episode (the `paper` protocol,
`hsgplan.evaluation.protocol`, which keeps only the perception rules below). Our loop lets a
failed primitive cost one step and goes on (the `recovering` protocol), and these hand-written
rules decide how it goes on. Each is named here, documented once, and switched off by name
(`hsgplan eval world --rules-off NAME,...`), so that what each buys is measured
(`--ablate-rules`; a rule that showed no gain on the tune split left, docs/decisions.md). None
of them consults the domain's rules (transition model, feasibility): they read only what the
agent saw and did.

Motion level (`hsgplan.motion.generator`):
- `failed_bins`: parameters that failed for good are remembered with the scene they failed in;
  in that unchanged scene the generator draws its next proposal from its own distribution over
  the bins not yet failed there, instead of proposing its best again (an agent does not repeat
  a refused action; the geometric sampler remembers its failures so too).
- `push_give_up`: after three failed pushes of an object from where it was put down, the
  generator gives up the spot: the agent takes the object up instead, and the place that put
  it there counts as failed, so that the next place draws another spot.

Task level (`hsgplan.planning.regression.planner`):
- `least_taken`: an action already taken from the very state observed now (with this goal)
  goes again only once every other action found there has been taken as often, rather than
  the search giving up.

Agents that check their actions (`hsgplan.agents.hierarchical`; the paper's does not):
- `refuse_repeats`: an action that succeeded from the very state observed now (with this goal)
  is refused as one that fails its check is: the agent came back here after it, so taking it
  again comes back again (a pick whose place the planner then trades for the open space, the
  object put down and taken up to the step limit). With every other action refused too, the
  refused ones go to clearing the way as they would; with none found but the repeats, they
  are taken as without the rule. It recovers from no failure (a state recurs without one), so
  the paper's protocol keeps it.
- `stuck_goal_literals`: when the task planner finds nothing ("regression stuck") while goal
  literals do not hold, the agent offers the action the paper's heuristic names for each of
  them, in the goal's order (the object's pick first where it is not held), to the same checks;
  the first that passes is taken, and those that fail go to clearing the way; with none taken
  the episode ends as the planner's would (`agents/stuck.py`). It too recovers from no
  failure, and the paper's protocol keeps it.

Perception (`hsgplan.sim.env`, seeing through a camera observer; nothing under the ground
truth). They recover from no failure, so the paper's protocol keeps them (`PERCEPTION_RULES`):
- `relook`: before a primitive on an object the belief is unsure of (not seen at the last
  look, or seen by a single view), or onto one, the arm moves to its rest pose, out of the
  cameras' way, and the robot looks again; the primitive is planned on that look. So too
  before the agent believes its goal reached while it is unsure of an object of the goal, and
  before it judges a step failed on a look unsure of the step's objects (the arm, where the
  step left it, hides the can it pushed into a shelf).
- `relook_failed`: before it judges any step failed on a look taken with the arm away from its
  rest pose, the arm moves there and the robot looks again (the arm, where a place left it,
  made a still can seem 17 cm off).
- `near_moves_only`: a neighbour whose belief moved between the looks before and after a step
  is judged moved by it only if the arm's links, what they carried or the object acted on came
  within 10 cm of it, in the robot's model along the joints the plan drove (`sim/reach.py`); a
  belief that moved farther off was put right by the new look.
- `seek_unseen`: while an object of the goal has been found by no view (a thin box under
  another object), the agent acts on the literals of the goal that name only objects it has
  seen, since moving them may bring the missing one into view; with no such literal left to
  reach, the episode ends as `never_seen`, as it does at once without the rule.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

from hsgplan.domain.errors import InvalidInputError

# The protocols an evaluation runs under (`hsgplan.evaluation.protocol`): the paper's, where the
# first failed primitive ends the episode and no rule recovers; ours, where the rules do.
PAPER, RECOVERING = "paper", "recovering"
PROTOCOLS = (PAPER, RECOVERING)


@dataclass(frozen=True)
class RecoveryRules:
    """Which recovery rules are on (all are, by default; the paper protocol keeps only the
    perception rules)."""

    failed_bins: bool = True
    push_give_up: bool = True
    least_taken: bool = True
    refuse_repeats: bool = True
    stuck_goal_literals: bool = True
    relook: bool = True
    relook_failed: bool = True
    near_moves_only: bool = True
    seek_unseen: bool = True

    @staticmethod
    def names() -> tuple[str, ...]:
        return tuple(f.name for f in fields(RecoveryRules))

    @staticmethod
    def none() -> RecoveryRules:
        return RecoveryRules(**dict.fromkeys(RecoveryRules.names(), False))

    def without(self, names) -> RecoveryRules:
        """These rules with `names` switched off; an unknown name refused in one line."""
        names = tuple(names)
        unknown = [n for n in names if n not in self.names()]
        if unknown:
            raise InvalidInputError(
                f"unknown recovery rule(s) {', '.join(unknown)} (known: {', '.join(self.names())})"
            )
        return replace(self, **dict.fromkeys(names, False))

    def off(self) -> tuple[str, ...]:
        """The names of the rules switched off."""
        return tuple(n for n in self.names() if not getattr(self, n))


# rules that act only when the agent sees through a camera observer; the paper's protocol keeps them
PERCEPTION_RULES = ("relook", "relook_failed", "near_moves_only", "seek_unseen")
# rules that act only in an agent that checks its actions
CHECKING_RULES = ("refuse_repeats", "stuck_goal_literals")
# rules that recover from no failure (a failed primitive ends an episode before any could act
# on it): the paper's protocol keeps them, switchable there too
NO_FAILURE_RULES = (*CHECKING_RULES, *PERCEPTION_RULES)
ALL_RULES = RecoveryRules()  # the recovering protocol's default: every rule on
