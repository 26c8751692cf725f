#!/usr/bin/env bash
# The published real-time Cosserat rod beside softarm on the steel rod:
# Till, Aloi and Rucker, "Real-time dynamics of soft and continuum robots
# based on Cosserat rod models" (IJRR 2019), their ContinuumRobotExamples,
# 02_Dynamics/00_Cosserat_Rod_PDE/Cpp (the rod with shear and extension, 40
# points, BDF-alpha at 2 ms with alpha = -0.2; Eigen ships in its Library/).
#
#   benches/peers/till_rod_pde.sh PATH/TO/ContinuumRobotExamples [REFERENCE_TRAJECTORY.csv]
#
# Builds the example unchanged but for writing its tip (till_rod_pde.patch)
# with g++ -O3 -march=native, runs it (it prints its own wall time and
# real-time ratio), and with a softarm trajectory.csv of
# examples/steel_rod.toml gives the largest tip distance between the two
# over 25 s (its rod lies along z with gravity along -x; softarm's along x
# with gravity along -z).
set -euo pipefail
src=$1
here=$(cd "$(dirname "$0")" && pwd)
work=$(cd "$here/../.." && pwd)/target/peers/till
rm -rf "$work" && mkdir -p "$work"
cp -r "$src/Library" "$src/02_Dynamics" "$work/"
cd "$work" && patch -s -p0 < "$here/till_rod_pde.patch"
cd "$work/02_Dynamics/00_Cosserat_Rod_PDE/Cpp"
g++ -O3 -march=native -DNDEBUG -std=c++17 -w -I ../../../Library -I ../../../Library/eigen main.cpp -o rod_pde
./rod_pde
if [ $# -ge 2 ]; then
  python3 - "$2" tip.csv <<'PY'
import csv, math, sys
def rows(path, along, across):
    with open(path, newline="") as f:
        return {round(float(r["t"]), 6): (float(r[along]), float(r[across])) for r in csv.DictReader(f)}
ours, theirs = rows(sys.argv[1], "tip_x", "tip_z"), rows(sys.argv[2], "tip_z", "tip_x")
common = sorted(set(ours) & set(theirs))
worst, at = max((math.dist(ours[t], theirs[t]), t) for t in common)
print(f"{len(common)} common times; largest tip distance {worst * 1e3:.2f} mm at t = {at} s; "
      f"at the start {math.dist(ours[0.0], theirs[0.0]) * 1e3:.2f} mm")
PY
fi
