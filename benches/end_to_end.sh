#!/usr/bin/env bash
# Fresh clone to the STIFF-FLOP result and to a passing test suite (the
# budgets of BENCHMARKS.md, build and tests): clone this repository, build the release binary
# from scratch (crates already downloaded), simulate the 54.65 s record;
# then, in a second fresh clone, run the README's test command from
# scratch. Prints the wall times.
# Usage: benches/end_to_end.sh [REPO] [WORKDIR]   (SKIP_TESTS=1: the first part only)
set -euo pipefail
repo=${1:-$(git -C "$(dirname "$0")/.." rev-parse --show-toplevel)}
work=${2:-$(mktemp -d)}
rm -rf "$work/e2e" "$work/e2e-tests"
start=$(date +%s.%N)
git clone -q "$repo" "$work/e2e"
cd "$work/e2e"
cloned=$(date +%s.%N)
cargo build --release --quiet
built=$(date +%s.%N)
./target/release/softarm simulate stiff_flop --out "$work/e2e-out" > /dev/null 2>&1
done_=$(date +%s.%N)
python3 - "$start" "$cloned" "$built" "$done_" "$work/e2e-out/summary.json" <<'PY'
import json, sys
s, c, b, d = map(float, sys.argv[1:5])
e = json.load(open(sys.argv[5]))["tip_error"]
print(f"main job: clone {c - s:.1f} s, build {b - c:.1f} s, simulate {d - b:.1f} s, total {d - s:.1f} s; "
      f"mean tip error {1e3 * e['mean_m']:.3f} mm")
PY
if [ "${SKIP_TESTS:-0}" = 1 ]; then exit 0; fi
git clone -q "$repo" "$work/e2e-tests"
cd "$work/e2e-tests"
t0=$(date +%s.%N)
cargo test --workspace --quiet > "$work/e2e-tests.log" 2>&1 || { tail -30 "$work/e2e-tests.log"; exit 1; }
t1=$(date +%s.%N)
python3 -c "import sys; print(f'tests: cargo test --workspace from a fresh clone {float(sys.argv[2]) - float(sys.argv[1]):.1f} s')" "$t0" "$t1"
