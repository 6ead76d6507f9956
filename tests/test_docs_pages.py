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
