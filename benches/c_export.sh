#!/usr/bin/env bash
# The exported C's state derivative, timed: benches/c_export.sh MODEL [SOFTARM]
# exports MODEL with SOFTARM (default target/release/softarm), compiles a
# driver with it at -O2 -march=native, and prints the best of seven
# batches of 1,000 evaluations at one state (BENCHMARKS.md, "Exported
# equations").
set -euo pipefail
model=$1
softarm=${2:-target/release/softarm}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
"$softarm" export "$model" --c "$dir" > /dev/null
prefix=$(ls "$dir"/*.h | xargs -n1 basename | sed 's/\.h$//')
up=$(echo "$prefix" | tr a-z A-Z)
cat > "$dir/bench.c" <<C
#include <stdio.h>
#include <time.h>
#include "$prefix.h"
int main(void) {
  static ${prefix}_params v; static ${prefix}_model m; static double x[${up}_NX], dx[${up}_NX];
  int i, k, batch;
  double best = 1e30;
  struct timespec a, b;
  ${prefix}_default_params(&v); ${prefix}_init(&m, &v);
  for (i = 0; i < ${up}_NX; i++) x[i] = 0.001 * ((i * 7919) % 13 - 6);
  for (batch = 0; batch < 7; batch++) {
    clock_gettime(CLOCK_MONOTONIC, &a);
    for (k = 0; k < 1000; k++) { x[0] += 1e-12; ${prefix}_state_derivative(&m, 0.1, x, dx); }
    clock_gettime(CLOCK_MONOTONIC, &b);
    double us = ((b.tv_sec - a.tv_sec) * 1e9 + (b.tv_nsec - a.tv_nsec)) / 1000 / 1e3;
    if (us < best) best = us;
  }
  printf("$model: %.2f us per state derivative, %ld bytes of C\n", best, 0L);
  return dx[0] != dx[0];
}
C
cc -std=gnu99 -O2 -march=native -I "$dir" "$dir/bench.c" "$dir/$prefix.c" -lm -o "$dir/bench"
"$dir/bench" | sed "s/, 0 bytes/, $(stat -c %s "$dir/$prefix.c") bytes/"
