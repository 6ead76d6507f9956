"""Every rule a run may switch off or set, read from where each is documented once: the
recovery rules from `domain/recovery.py`'s bullets, f_p's and the motion planner's from their
settings' `Args:` (`perception/rules.py`, `sim/plan_rules.py`). `hsgplan rules` prints them.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, fields

from hsgplan.domain import recovery
from hsgplan.domain.recovery import CHECKING_RULES, NO_FAILURE_RULES, PERCEPTION_RULES
from hsgplan.perception.rules import PerceptionRules
from hsgplan.sim.plan_rules import PlanRules


@dataclass(frozen=True)
class Rule:
    """One rule: the option that sets it, its name, its shipped value, whether the paper's
    protocol keeps it, and the first sentence of its documentation."""

    option: str
    name: str
    shipped: str
    paper: bool
    what: str


def _first_sentence(text: str) -> str:
    """Up to the first full stop or semicolon, ended with a full stop."""
    flat = " ".join(text.split())
    first = re.match(r"(.*?)[.;](\s|$)", flat)
    return (first.group(1) if first else flat.rstrip(".")) + "."


def _bullets(doc: str) -> dict[str, str]:
    """`- `name`: text` bullets of a docstring, each with its continuation lines."""
    found = re.findall(r"^- `(\w+)`: (.*?)(?=^- `|^\S|\Z)", doc, re.M | re.S)
    return {name: text for name, text in found}


def _args(doc: str) -> dict[str, str]:
    """`name: text` entries of a docstring's `Args:` section, continuation lines indented."""
    section = doc.split("Args:", 1)[1]
    found = re.findall(r"^\s{0,4}(\w+): (.*?)(?=^\s{0,4}\w+: |\Z)", section, re.M | re.S)
    return {name: text for name, text in found}


def _shown(value: object) -> str:
    if isinstance(value, bool):
        return "on" if value else "off"
    return str(value)


def rules() -> list[Rule]:
    """Every rule, by the option that sets it; a rule without its documentation raises."""
    out = []
    docs = _bullets(recovery.__doc__ or "")
    for name in recovery.RecoveryRules.names():
        group = (
            "perception"
            if name in PERCEPTION_RULES
            else "checking"
            if name in CHECKING_RULES
            else ""
        )
        what = _first_sentence(docs[name])
        option = "--rules-off" + (f" ({group})" if group else "")
        out.append(Rule(option, name, "on", name in NO_FAILURE_RULES, what))
    for option, settings in (
        ("--perception-rules", PerceptionRules()),
        ("--plan-rules", PlanRules()),
    ):
        docs = _args(type(settings).__doc__ or "")
        for f in fields(settings):
            value = _shown(getattr(settings, f.name))
            out.append(Rule(option, f.name, value, True, _first_sentence(docs[f.name])))
    return out
