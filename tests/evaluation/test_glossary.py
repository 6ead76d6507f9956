"""Every name a results table prints is said once, from the code's own enums."""

from pathlib import Path

from hsgplan.evaluation.failures import Failure
from hsgplan.evaluation.glossary import COLUMNS, ENDINGS, STATUSES, glossary
from hsgplan.evaluation.summary import EXECUTION, OVERSTEP, PERCEPTION, class_of
from hsgplan.sim.outcome import Status

PAGE = Path(__file__).resolve().parents[2] / "docs" / "failures.md"


def test_every_status_ending_and_column_has_a_meaning():
    assert set(STATUSES) == set(Status) and set(ENDINGS) == set(Failure)
    said = [*STATUSES.values(), *ENDINGS.values(), *COLUMNS.values()]
    assert all(text.endswith(".") for text in said)


def test_the_classes_are_the_summarys():
    assert class_of(Failure.NO_SUBGOAL) == OVERSTEP
    assert class_of(Failure.FAILED_PRIMITIVE) == EXECUTION
    assert class_of(Failure.NEVER_SEEN) == PERCEPTION


def test_the_reference_page_is_what_the_code_says():
    """docs/failures.md's block is `glossary()` as printed: a status added or renamed in the
    code and not on the page fails here (refresh: scripts/refresh_readme.py failure-names)."""
    text = PAGE.read_text(encoding="utf-8")
    block = text.split("<!-- BEGIN failure-names -->\n", 1)[1].split("\n_Produced by", 1)[0]
    assert block.strip() == glossary().strip()
