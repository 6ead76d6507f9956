"""What each recovery rule buys: Table 1 under the recovering protocol with every rule on, then
with each rule off in turn (`hsgplan eval world --ablate-rules`).

Each variant is a whole Table 1 run of its own (`evaluation/table1.py`) in a folder under the
ablation's, named by the rule switched off (`all-rules` for none), so an interrupted ablation
resumes where it stopped. The result is one table: a row per variant, the success rate per
method and size, and the failed primitives per episode.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, replace
from pathlib import Path

from hsgplan.agents.registry import CHECKED_PLANNERS, WHOLE_AGENTS, agent_parts
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.recovery import CHECKING_RULES, PAPER, PERCEPTION_RULES, RecoveryRules
from hsgplan.evaluation.config import EvalConfig
from hsgplan.evaluation.episode import EpisodeRecord
from hsgplan.evaluation.table1 import (
    Method,
    TextTable,
    check_table,
    label,
    run_table,
    table_settings,
)
from hsgplan.runner.run_folder import check_claim, claim

ALL_RULES_ON = "all-rules"


def variants(
    config: EvalConfig, seeing: bool = False, checking: bool = False
) -> dict[str, EvalConfig]:
    """The configurations compared, by folder name: every rule on, then each one off (the
    perception rules only where some method sees through f_p, `seeing`: under the ground
    truth they do nothing; the checking agents' rules only where some method's agent checks
    its actions, `checking`)."""
    if config.protocol == PAPER or config.rules_off:
        raise InvalidInputError(
            "--ablate-rules switches each recovery rule off in turn under the recovering "
            "protocol; give --protocol recovering and no --rules-off"
        )
    out = {ALL_RULES_ON: config}
    rules = [
        r
        for r in RecoveryRules.names()
        if (seeing or r not in PERCEPTION_RULES) and (checking or r not in CHECKING_RULES)
    ]
    out |= {f"no-{rule}": replace(config, rules_off=(rule,)) for rule in rules}
    return out


def _seeing(methods: list[Method]) -> bool:
    return any(m.perception != "gt" for m in methods)


def _checking(methods: list[Method]) -> bool:
    parts = [agent_parts(m.agent) for m in methods if m.agent not in WHOLE_AGENTS]
    return any(planner in CHECKED_PLANNERS for planner, _ in parts)


ABLATION_KIND = "eval-ablation"


def _claimed_with(methods: list[Method], config: EvalConfig) -> tuple[dict, str]:
    settings = table_settings(config) | {"methods": [asdict(m) for m in methods]}
    return settings, "the folder holds an ablation of another configuration; use another --out"


def check_ablation(methods: list[Method], config: EvalConfig, out: Path) -> list[str]:
    """Every refusal of the ablation's folder and its variants', before anything is written;
    the variants."""
    check_claim(out, ABLATION_KIND, *_claimed_with(methods, config))
    names = variants(config, _seeing(methods), _checking(methods))
    for name, variant in names.items():
        check_table(methods, variant, out / name)
    return list(names)


def run_ablation(
    methods: list[Method],
    config: EvalConfig,
    out: Path,
    workers: int = 2,
    ray: str | None = None,
    on_episode: Callable[[EpisodeRecord], None] | None = None,
) -> dict:
    """Every variant's Table 1 (resumable); `{"variants": {NAME: report}}`."""
    check_ablation(methods, config, out)
    claim(out, ABLATION_KIND, *_claimed_with(methods, config))
    reports = {
        name: run_table(methods, variant, out / name, workers, ray, on_episode)
        for name, variant in variants(config, _seeing(methods), _checking(methods)).items()
    }
    return {"protocol": config.protocol, "variants": reports, "run": str(out)}


def ablation_table(report: dict) -> TextTable:
    """Success rate per method and size, and failed primitives per episode, per variant."""
    first = next(iter(report["variants"].values()))
    methods = list(first["methods"])
    sizes = sorted({int(n) for s in first["methods"].values() for n in s["by_size"]})
    header = ["recovery rules"] + [f"{label(m)} {n}" for m in methods for n in sizes]
    header += [f"{label(m)} failed primitives / episode" for m in methods]
    rows = []
    for name, r in report["variants"].items():
        row = ["all on" if name == ALL_RULES_ON else f"{name.removeprefix('no-')} off"]
        for m in methods:
            by_size = r["methods"][m]["by_size"]
            row += [f"{by_size[str(n)]['success_rate']:.2f}" for n in sizes]
        for m in methods:
            by_size = r["methods"][m]["by_size"].values()
            episodes = sum(v["episodes"] for v in by_size)
            row.append(f"{sum(v['failed_primitives'] for v in by_size) / episodes:.2f}")
        rows.append(tuple(row))
    source = first["goals_file"] or f"{first['goals']} random goals per size"
    title = (
        f"Success rate with each recovery rule off in turn (recovering protocol): {source}, "
        f"each run {_times(first['repeats'])}, seed {first['seed']}"
    )
    return TextTable(title, tuple(header), tuple(rows))


def _times(repeats: int) -> str:
    return "once" if repeats == 1 else f"{repeats} times"
