"""Where every training label of a set of networks comes from, and who labelled it
(`hsgplan labels`): each task network's sources with their counts (its `labels.json`), each
motion network's examples (its data's successes, or every trial, and the scenes held out), so
that a table says how much supervision a result stands on, and which of it a hand-written rule
made."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from hsgplan.domain.checks import read_json
from hsgplan.domain.errors import InvalidInputError

# who labels each source of a task network's examples
WHO = {
    "demonstrations": "the oracle's 18 demonstrations",
    "copies with added objects": (
        "the demonstrations with objects added where domain/room.py's capacity rules leave "
        "room: a hand-written rule inside these labels"
    ),
    "primitives executed in the simulated world": "staged states, each primitive run under physics",
    "primitives executed from states the agent visited": (
        "states the agent reached on training-split goals, each primitive run under physics"
    ),
    "demonstrated changes": "what the demonstrations made true (positives only)",
    "demonstrated changes and their alterations": (
        "the paper's recipe: demonstrated changes, negatives by altering their edges"
    ),
    "demonstrated changes and their other predicates": (
        "demonstrated changes, negatives by other predicates of the same edges"
    ),
}
# the task planner's two networks (the forward baseline's are no agent's that a table reports)
TASK_NETWORKS = {"preimage": "f_preimage", "reach": "f_reach"}


@dataclass(frozen=True)
class LabelRow:
    network: str
    source: str
    examples: int
    labels: int
    by_class: str
    who: str


def label_rows(checkpoint: Path) -> list[LabelRow]:
    """The rows of a task checkpoint folder or of a motion network's folder."""
    checkpoint = Path(checkpoint)
    if (checkpoint / "training.json").is_file():
        return [_motion_row(checkpoint)]
    rows = []
    for name, network in TASK_NETWORKS.items():
        path = checkpoint / name / "labels.json"
        if not path.is_file():
            continue
        for source, counts in read_json(path, "label counts").items():
            rows.append(
                LabelRow(
                    f"{checkpoint.name}: {network}",
                    source,
                    counts["examples"],
                    counts["labels"],
                    " / ".join(map(str, counts["by_class"])),
                    WHO.get(source, "—"),
                )
            )
    if not rows:
        raise InvalidInputError(
            f"'{checkpoint}' is no task checkpoint with label counts nor a motion network"
        )
    return rows


def _motion_row(folder: Path) -> LabelRow:
    config = read_json(folder / "train_config.json", "training configuration")
    kept = read_json(folder / "training.json", "training selection")
    every = config.get("loss") == "bce"
    source = f"{config['data']}: {'every trial' if every else 'successful trials'}"
    if held := kept.get("validation_examples", 0):
        source += f" ({held} more held out to choose the epoch)"
    return LabelRow(
        f"{folder.parent.name}/{folder.name}",
        source,
        kept["training_examples"],
        kept["training_examples"],
        "—",
        "each staged trial run under physics: whether its effect held",
    )
