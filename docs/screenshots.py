"""Screenshots of every scene as a projector shows it, for the README and docs/.

Run from the repository root (Debian's Chromium and the package installed):

    .venv/bin/python docs/screenshots.py

Each scene is served on a free port, opened in headless Chromium at 1280x720 and
1600x900, left to run a few seconds, and saved as ``docs/<scene>-<width>x<height>.png``.
"""

from __future__ import annotations

import socket
import sys
import time
from pathlib import Path

from playwright.sync_api import sync_playwright

from sandbox.scenes import SCENES
from sandbox.web.serving.app import start

SIZES = ((1280, 720), (1600, 900))
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]
SETTLE_S = 6.0  # page load, first frames, plots filling


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def main(out: Path, scenes: list[str]) -> None:
    out.mkdir(parents=True, exist_ok=True)
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path="/usr/bin/chromium", args=CHROMIUM_ARGS)
        for name in scenes:
            app = start(name, port=free_port(), open_message=False)
            try:
                for width, height in SIZES:
                    page = browser.new_page(viewport={"width": width, "height": height})
                    page.goto(f"http://127.0.0.1:{app.port}/")
                    time.sleep(SETTLE_S)
                    # viser's software-rendering warning (headless, no GPU) closes itself
                    # after 8 s; the README shows the page as on a GPU, without it.
                    page.wait_for_selector("[role=alert]", state="detached", timeout=20_000)
                    time.sleep(0.5)
                    path = out / f"{name}-{width}x{height}.png"
                    page.screenshot(path=str(path))
                    page.close()
                    print(path)
            finally:
                app.stop()
        browser.close()


if __name__ == "__main__":
    main(Path(__file__).parent, sys.argv[1:] or list(SCENES))
