"""A PNG of an HTML page as headless Chromium shows it (the README's picture of the report).

Usage: python scripts/screenshot.py PAGE.html OUT.png [--width 1300] [--height 1500]

Needs Debian's chromium (`apt-get install chromium`) and the dev extra (playwright).
"""

from __future__ import annotations

import argparse
import shutil
import sys
from pathlib import Path


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("page", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--width", type=int, default=1300)
    parser.add_argument("--height", type=int, default=1500)
    parser.add_argument("--scroll-to", default="", help="CSS selector to scroll into view first")
    args = parser.parse_args(argv)
    chromium = shutil.which("chromium")
    if chromium is None or not args.page.is_file():
        print("error: needs Debian's chromium and an existing page", file=sys.stderr)
        return 2
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        browser = p.chromium.launch(
            executable_path=chromium,
            args=["--no-sandbox", "--disable-gpu", "--disable-background-networking"],
        )
        page = browser.new_page(viewport={"width": args.width, "height": args.height})
        page.goto(args.page.resolve().as_uri())
        page.wait_for_load_state("load")
        if args.scroll_to:
            page.locator(args.scroll_to).first.scroll_into_view_if_needed()
        page.screenshot(path=str(args.out))
        browser.close()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
