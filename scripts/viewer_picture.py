"""A picture of rerun's viewer on a recording, for the docs: the web viewer served from the
recording (`rerun --serve-web`) opened in headless Chromium (Debian's `chromium`, driven by
Playwright), its window saved as a PNG once the recording has loaded.

    .venv/bin/python scripts/viewer_picture.py runs/demo/episode.rrd docs/rerun-viewer.png
"""

from __future__ import annotations

import argparse
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

from playwright.sync_api import sync_playwright

CHROMIUM_FLAGS = [
    "--no-sandbox",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
    "--disable-quic",
    "--use-angle=swiftshader",  # WebGL on the CPU: the machine has no GPU
    "--enable-unsafe-swiftshader",
]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("recording", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--wait", type=float, default=45.0, help="seconds to let it load")
    parser.add_argument("--size", default="1600x1000")
    args = parser.parse_args()
    if not args.recording.is_file():
        sys.exit(f"error: no recording at {args.recording}")
    rerun = shutil.which("rerun", path=str(Path(sys.executable).parent)) or "rerun"
    web, grpc = free_port(), free_port()
    server = subprocess.Popen(
        [
            rerun,
            "--serve-web",
            "--web-viewer-port",
            str(web),
            "--port",
            str(grpc),
            str(args.recording),
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,  # `rerun` starts the viewer's own binary: both end together
    )
    width, height = (int(v) for v in args.size.split("x"))
    try:
        time.sleep(3)
        url = f"http://127.0.0.1:{web}?url=rerun%2Bhttp%3A%2F%2Flocalhost%3A{grpc}%2Fproxy"
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path="/usr/bin/chromium", args=CHROMIUM_FLAGS)
            page = browser.new_page(viewport={"width": width, "height": height})
            page.goto(url)
            time.sleep(args.wait)
            page.screenshot(path=str(args.out))
            browser.close()
    finally:
        os.killpg(server.pid, signal.SIGTERM)
        server.wait()
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
