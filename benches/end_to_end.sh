#!/usr/bin/env bash
# The build budgets of BENCHMARKS.md, measured from fresh clones: the
# README's main job from nothing (a fresh cargo home: download the crates
# for this machine's target, build the release binary, simulate the 54.65 s
# STIFF-FLOP record); adding a one-segment model of a new structure and
# `cargo build --release` again; the size of generated/; then, in a second
# fresh clone, the README's test command from scratch (crates already
# downloaded). Prints the wall times and a table of the four.
# Usage: benches/end_to_end.sh [REPO] [WORKDIR]   (SKIP_TESTS=1: the first part only)
set -euo pipefail
repo=${1:-$(git -C "$(dirname "$0")/.." rev-parse --show-toplevel)}
work=${2:-$(mktemp -d)}
rm -rf "$work/e2e" "$work/e2e-tests" "$work/cargo-home"
host=$(rustc -vV | sed -n 's/^host: //p')
start=$(date +%s.%N)
git clone -q "$repo" "$work/e2e"
cd "$work/e2e"
cloned=$(date +%s.%N)
CARGO_HOME="$work/cargo-home" cargo fetch --quiet --target "$host"
fetched=$(date +%s.%N)
CARGO_HOME="$work/cargo-home" cargo build --release --quiet
built=$(date +%s.%N)
./target/release/softarm simulate stiff_flop --out "$work/e2e-out" > /dev/null 2>&1
done_=$(date +%s.%N)
python3 - "$start" "$cloned" "$fetched" "$built" "$done_" "$work/e2e-out/summary.json" <<'PY'
import json, sys
s, c, f, b, d = map(float, sys.argv[1:6])
e = json.load(open(sys.argv[6]))["tip_error"]
print(f"main job: clone {c - s:.1f} s, download {f - c:.1f} s, build {b - f:.1f} s, simulate {d - b:.1f} s, total {d - s:.1f} s; "
      f"mean tip error {1e3 * e['mean_m']:.3f} mm")
PY
# A one-segment model of a structure no bundled model has.
cat > models/e2e_new_arm.toml <<'TOML'
name = "e2e_new_arm"
dimensions = 3
gravity = [0.0, 0.0, -9.81]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "pcc"
length = 0.2
elements = 7
density = 1100.0
outer_radius = 0.01
youngs_modulus = 5e5
TOML
added0=$(date +%s.%N)
CARGO_HOME="$work/cargo-home" cargo build --release --quiet
added1=$(date +%s.%N)
rm models/e2e_new_arm.toml
git checkout -q -- generated && git clean -fdq generated
sizes=$(python3 - <<'PY'
import glob, os
files = [f for f in glob.glob("generated/*.rs") if os.path.basename(f) not in ("mod.rs", "lib.rs")]
total = sum(os.path.getsize(f) for f in glob.glob("generated/**", recursive=True) if os.path.isfile(f))
big = max(files, key=os.path.getsize)
print(f"{total / 1e6:.2f} MB (largest {os.path.basename(big)} {os.path.getsize(big) / 1e3:.0f} kB)")
PY
)
main_s=$(python3 -c "import sys; print(f'{float(sys.argv[2]) - float(sys.argv[1]):.1f}')" "$start" "$done_")
download_s=$(python3 -c "import sys; print(f'{float(sys.argv[2]) - float(sys.argv[1]):.1f}')" "$cloned" "$fetched")
added_s=$(python3 -c "import sys; print(f'{float(sys.argv[2]) - float(sys.argv[1]):.1f}')" "$added0" "$added1")
tests_s="(skipped)"
table() {
  echo "| what | now | goal |"
  echo "|---|---|---|"
  echo "| \`cargo run --release -- simulate stiff_flop\` from nothing (download $download_s s) | $main_s s | < 90 s |"
  echo "| \`cargo test --workspace\` from a fresh clone | $tests_s s | < 300 s |"
  echo "| adding a one-segment model, \`cargo build --release\` | $added_s s | < 30 s |"
  echo "| generated/ | $sizes | < 2 MB, no model over 300 kB |"
}
if [ "${SKIP_TESTS:-0}" = 1 ]; then table; exit 0; fi
git clone -q "$repo" "$work/e2e-tests"
cd "$work/e2e-tests"
t0=$(date +%s.%N)
cargo test --workspace --quiet > "$work/e2e-tests.log" 2>&1 || { tail -30 "$work/e2e-tests.log"; exit 1; }
t1=$(date +%s.%N)
tests_s=$(python3 -c "import sys; print(f'{float(sys.argv[2]) - float(sys.argv[1]):.1f}')" "$t0" "$t1")
table
