#!/usr/bin/env python3
"""Check softarm's viewer.html in a real headless browser (Debian's chromium).

Usage: check_viewer.py OUT_DIR   (a folder `softarm animate` wrote)

The page, opened with ?check, steps its time slider to four frames and
reports, for each, the end of the arm it drew (from shape.csv's rows in
the page), the colour under it and under the middle of the arm. Checked
against the run's trajectory.csv, an independent output (the compiled
Outputs kernel's tip):

* the drawn arm ends at the trajectory's tip at that time (1e-8 m);
* the pixel there is the tip marker's pure red: the marker, placed from
  trajectory.csv, sits where the rendered tube ends on screen;
* the pixel at the arm's middle is tube-coloured (blue dominant), not the
  background: the tube was rendered.

Standard library only; exits non-zero with the reason on any failure.
"""

import csv
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path


def browser():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    sys.exit("check_viewer: no chromium on PATH (apt-get install chromium)")


def page_report(html):
    cmd = [
        browser(),
        "--headless",
        "--no-sandbox",
        "--use-angle=swiftshader",
        "--enable-unsafe-swiftshader",
        "--window-size=800,600",
        "--dump-dom",
        html.resolve().as_uri() + "?check",
    ]
    dom = subprocess.run(cmd, capture_output=True, text=True, timeout=120).stdout
    m = re.search(r'<pre id="check">(.*?)</pre>', dom, re.S)
    if not m or not m.group(1).strip():
        sys.exit("check_viewer: the page reported nothing (did its script run?)")
    return json.loads(m.group(1))


def main():
    out = Path(sys.argv[1])
    report = page_report(out / "viewer.html")
    if not report["webgl"]:
        sys.exit("check_viewer: no WebGL context in the browser")
    with open(out / "trajectory.csv") as f:
        rows = list(csv.DictReader(f))
    tips = {float(r["t"]): [float(r[c]) for c in ("tip_x", "tip_y", "tip_z")] for r in rows}
    failures = []
    for fr in report["frames"]:
        t = fr["t"]
        tip = min(tips.items(), key=lambda kv: abs(kv[0] - t))
        if abs(tip[0] - t) > 1e-9:
            failures.append(f"frame {fr['frame']}: t = {t} is not a trajectory row")
            continue
        err = max(abs(a - b) for a, b in zip(fr["drawn_end"], tip[1]))
        if err > 1e-8:
            failures.append(f"t = {t}: drawn end {fr['drawn_end']} vs tip {tip[1]} ({err:.2e} m)")
        r, g, b, _ = fr["end_pixel"]
        if not (r > 240 and g < 15 and b < 15):
            failures.append(f"t = {t}: pixel at the drawn end is {fr['end_pixel']}, not the tip marker")
        r, g, b, _ = fr["middle_pixel"]
        if not (b > r + 30 and b > g):
            failures.append(f"t = {t}: pixel at the arm's middle is {fr['middle_pixel']}, not the tube")
        print(f"t = {t:8.4f} s  drawn end vs tip {err:.1e} m  end pixel {fr['end_pixel']}  "
              f"middle pixel {fr['middle_pixel']}")
    if failures:
        sys.exit("check_viewer: FAILED\n  " + "\n  ".join(failures))
    print(f"check_viewer: {len(report['frames'])} frames agree with trajectory.csv")


if __name__ == "__main__":
    main()
