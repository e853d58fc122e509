"""Open a designopt view.html in headless Chromium (Debian's package) and save screenshots: the first frame and
the middle one (view.html#frame=N; a closed path ends where it starts), with the network disabled, so that a
person can look at them and the script can check that the page rendered and that the frames move the robot.

    python benchmarks/view_screenshot.py results/milling/<run>/view.html [--out docs/figures]

Needs /usr/bin/chromium (apt-get install chromium). Not part of `make test`: it is a check of the browser, run
by hand or by `make view-check`; what it showed is recorded in docs/benchmarks.md.
"""

from __future__ import annotations

import argparse
import re
import shutil
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from matplotlib.image import imread


def screenshot(html: Path, png: Path, fragment: str = "", size=(1280, 900)) -> None:
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if chromium is None:
        sys.exit("no chromium on PATH: apt-get install chromium")
    with tempfile.TemporaryDirectory() as profile:
        subprocess.run([
            chromium, "--headless=new", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader", f"--user-data-dir={profile}", "--proxy-server=127.0.0.1:9",
            "--proxy-bypass-list=<-loopback>", f"--window-size={size[0]},{size[1]}", "--virtual-time-budget=15000",
            "--hide-scrollbars", f"--screenshot={png}", html.resolve().as_uri() + fragment,
        ], check=True, capture_output=True, timeout=120)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("html", type=Path)
    parser.add_argument("--out", type=Path, default=Path("docs/figures"))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    frames = len(re.findall(r'"name":"\d+"', args.html.read_text()))
    first, last = args.out / "view_first.png", args.out / "view_middle.png"
    screenshot(args.html, first)
    screenshot(args.html, last, f"#frame={frames // 2}")
    a, b = imread(first)[..., :3], imread(b_path := last)[..., :3]
    coloured = float(np.mean(a.std(axis=2) > 0.05))  # share of pixels that are not grey/white: something drew
    moved = float(np.mean(np.abs(a - b).sum(axis=2) > 0.1))
    print(f"{args.html}: {frames} frames; first frame {first} ({coloured:.1%} coloured pixels); middle frame "
          f"{b_path}; {moved:.2%} of the pixels differ between them")
    ok = coloured > 0.01 and moved > 0.001
    print("renders and animates" if ok else "DID NOT RENDER OR DID NOT MOVE")
    return 0 if ok else 1


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    sys.exit(main())
