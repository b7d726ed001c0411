#!/bin/sh
# Runs the libFuzzer targets (fuzz_frame, fuzz_gltf, fuzz_image) for a given
# time each and prints, per target, the executions it reached and what it
# found (crash-*, leak-*, timeout-*, oom-* files). Results go to docs/fuzzing.md
# by hand (the issue's goal: >= 10^7 executions of each with no finding).
#   sh scripts/fuzz-long.sh [SECONDS_EACH] [TARGET...]   (default 3600, all)
# New inputs go to build-fuzz/corpus*, as in scripts/test.sh; the seeds in tests/fuzz are only read.
set -eu
cd "$(dirname "$0")/.."
secs="${1:-3600}"
[ $# -gt 0 ] && shift
targets="${*:-fuzz_frame fuzz_gltf fuzz_image}"
cmake --fresh -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang \
  -DCMAKE_CXX_COMPILER=clang++ -DLPVD_FUZZ=ON >/dev/null
# shellcheck disable=SC2086
cmake --build build-fuzz --target $targets -j "$(nproc)" >/dev/null
for t in $targets; do
  extra=
  case "$t" in
    fuzz_frame) seeds=tests/fuzz/corpus; corpus=build-fuzz/corpus; maxlen=65536 ;;
    fuzz_gltf) seeds=tests/fuzz/corpus_gltf; corpus=build-fuzz/corpus-gltf; maxlen=1048576 ;;
    fuzz_image) seeds=tests/fuzz/corpus_image; corpus=build-fuzz/corpus-image; maxlen=1048576
      # stb reserves (never touches) 2 GiB for a bogus zlib stored block: docs/fuzzing.md
      extra=-malloc_limit_mb=4096 ;;
    *) echo "fuzz-long: unknown target $t" >&2; exit 2 ;;
  esac
  out="build-fuzz/findings-$t"
  mkdir -p "$corpus" "$out"
  log="build-fuzz/$t.log"
  start=$(date +%s)
  rc=0
  # shellcheck disable=SC2086
  "./build-fuzz/fuzz/$t" -max_total_time="$secs" -rss_limit_mb=2048 ${extra:-} -max_len="$maxlen" -timeout=30 \
    -print_final_stats=1 -artifact_prefix="$out/" "$corpus" "$seeds" >"$log" 2>&1 || rc=$?
  took=$(( $(date +%s) - start ))
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
  found=$(find "$out" -type f | wc -l)
  echo "$t: ${execs:-?} executions in ${took} s, exit $rc, $found finding(s) in $out (log: $log)"
done
