"""The README and docs/ describe the product as it is: no page keeps a dated changelog (a date
belongs in a block's stamp, which a command wrote), and the README's prose stays a manual."""

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
BLOCK = re.compile(r"<!-- BEGIN .*?<!-- END [^>]*-->", re.S)
DATE = re.compile(r"\b20\d\d-\d\d-\d\d\b")


def outside_blocks(text: str) -> str:
    """A page's own words: blocks a command pasted (and their stamps) left out."""
    return BLOCK.sub("", text)


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_no_page_dates_its_own_words(page):
    dated = DATE.findall(outside_blocks(page.read_text(encoding="utf-8")))
    assert dated == [], f"{page.name} dates its prose: {dated}"


def test_a_date_in_prose_is_caught_and_one_in_a_stamp_is_not():
    stamped = "<!-- BEGIN t -->\n| a |\n\n_Produced by `x` on 2026-12-01._\n<!-- END t -->\n"
    assert DATE.findall(outside_blocks(stamped)) == []
    assert DATE.findall(outside_blocks(stamped + "Since 2026-11-26 the arm moves.")) != []


def test_the_readmes_prose_is_at_most_1500_words():
    text = outside_blocks((ROOT / "README.md").read_text(encoding="utf-8"))
    text = re.sub(r"```.*?```", "", text, flags=re.S)
    prose = [line for line in text.splitlines() if not line.startswith(("|", "![", "<!--", "#"))]
    assert len(" ".join(prose).split()) <= 1500


# a rate (0.83, 1.00) or a ratio (34×) in prose is a measurement: it must be one a command wrote
MEASURED = re.compile(r"(?<![\w.])(?:[01]\.\d\d|\d+×)(?![\w.])")


def unmeasured(prose: str, blocks: str) -> list[str]:
    """The rates and ratios in `prose` that no pasted block holds."""
    return [n for n in MEASURED.findall(prose) if n not in blocks]


def test_a_rate_in_the_readmes_prose_is_one_a_block_holds():
    blocks = "".join(BLOCK.findall("".join(p.read_text(encoding="utf-8") for p in PAGES)))
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert unmeasured(outside_blocks(readme), blocks) == []


def test_a_typed_rate_is_caught_and_a_pasted_one_is_not():
    blocks = "<!-- BEGIN t -->\n| 0.96 | 34× |\n<!-- END t -->"
    assert unmeasured("reads 0.96, 34× faster", blocks) == []
    assert unmeasured("reads 0.97 at 6 objects, 35× faster", blocks) == ["0.97", "35×"]


def test_docs_stay_a_reference_one_sitting_long():
    words = {p.name: len(p.read_text(encoding="utf-8").split()) for p in PAGES[1:]}
    assert sum(words.values()) <= 15000, words
    assert max(words.values()) <= 4000, words
