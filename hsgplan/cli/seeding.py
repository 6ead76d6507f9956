"""The options that say which seeds a command draws (a split, a bare seed, trainings) and which
rules it runs under, and `hsgplan rules`, which lists those rules."""

from __future__ import annotations

from typing import Annotated

import typer

from hsgplan.cli.common import MarkdownFlag, bounded_option, choice, print_table, refuses_bad_input

SplitName = choice("SplitName", ("tune", "test"))
SplitOption = Annotated[
    SplitName | None,
    typer.Option(
        help="Draw the goals and start scenes from a split (docs/splits.md): test, for a "
        "published number; tune, for choosing. Without it a run is exploration.",
        metavar="SPLIT",
    ),
]
SeedOrSplitStart = Annotated[
    int | None,
    bounded_option(
        "seed", "Seed of the goals and the episodes (default: 0, or the split's first)."
    ),
]


TrainingSeeds = Annotated[
    int | None,
    typer.Option(
        help="Train K times, with the configuration's seed and the K-1 after it, seed S into "
        "OUT/seed-S (docs/retraining.md, Trainings).",
        min=1,
        metavar="K",
    ),
]


PerceptionRulesOption = Annotated[
    str,
    typer.Option(
        "--perception-rules",
        help="f_p's rules set otherwise, comma-separated NAME=VALUE (e.g. pixel_vote=off,"
        "ray_gap=0.03; the names: hsgplan rules).",
        metavar="RULES",
    ),
]


PlanRulesOption = Annotated[
    str,
    typer.Option(
        "--plan-rules",
        help="The motion planner's rules set otherwise, comma-separated NAME=VALUE (e.g. "
        "descent_points=0; the names: hsgplan rules).",
        metavar="RULES",
    ),
]


def rule_settings(text: str) -> tuple[str, ...]:
    """The `--perception-rules` settings, each checked (a bad one refused in one line)."""
    from hsgplan.perception.rules import PerceptionRules

    return PerceptionRules.parse(text).changed()


def plan_rule_settings(text: str) -> tuple[str, ...]:
    """The `--plan-rules` settings, each checked."""
    from hsgplan.sim.plan_rules import PlanRules

    return PlanRules.parse(text).changed()


def split_seed(seed: int | None, split) -> int:
    """The run's seed: the one given, else the split's first seed, else 0."""
    if seed is not None:
        return seed
    if split is None:
        return 0
    from hsgplan.evaluation.splits import split_named

    return split_named(split.value).seeds.start


@refuses_bad_input
def rules(
    markdown: MarkdownFlag = False,
) -> None:
    """Every rule a run may switch off or set: the recovery rules (--rules-off), f_p's
    (--perception-rules) and the motion planner's (--plan-rules), each as shipped."""
    from hsgplan.evaluation.rule_list import rules as every_rule

    rows = [
        (r.option, r.name, r.shipped, "kept" if r.paper else "off", r.what) for r in every_rule()
    ]
    print_table(
        "The rules a run may switch off or set: as shipped, under the paper's protocol, and "
        "what each does (documented in domain/recovery.py, perception/rules.py, "
        "sim/plan_rules.py)",
        ("option", "rule", "shipped", "paper protocol", "what it does"),
        rows,
        markdown,
    )
