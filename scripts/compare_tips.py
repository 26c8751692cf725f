"""Compare the tip of two runs at their common times.

    python3 scripts/compare_tips.py A.csv B.csv TOLERANCE_M

Each file has columns t, tip_x, tip_y and, in 3D, tip_z (more are
ignored); the difference is the distance between the tips. Exits nonzero
when the tips differ by more than TOLERANCE_M metres at any time both
files hold (to 1e-6 s), or when they share fewer than ten times. CI
compares examples/c's fixed-step run of the exported C with
`softarm simulate` this way.
"""

import csv
import sys


def tips(path):
    with open(path, newline="") as f:
        return {
            round(float(r["t"]), 6): tuple(float(r[c]) for c in ("tip_x", "tip_y", "tip_z") if c in r)
            for r in csv.DictReader(f)
        }


def main():
    a, b, tol = tips(sys.argv[1]), tips(sys.argv[2]), float(sys.argv[3])
    common = sorted(set(a) & set(b))
    if len(common) < 10:
        sys.exit(f"only {len(common)} common times")
    worst, at = max((sum((x - y) ** 2 for x, y in zip(a[t], b[t])) ** 0.5, t) for t in common)
    print(f"{len(common)} common times; largest tip difference {worst:.3e} m at t = {at} s")
    if not worst <= tol:
        sys.exit(f"above the tolerance {tol:g} m")


if __name__ == "__main__":
    main()
