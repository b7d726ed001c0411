#!/bin/sh
# build_baseline.sh REV DIR - builds lpvd-bench of an earlier revision REV in
# DIR (a git worktree) with this checkout's bench source, so both builds run
# the same configurations and print the same rows; then compare them side by
# side in one run:
#
#   sh bench/build_baseline.sh 7839bf4 ../lpvd-base
#   python3 bench/compare_builds.py --baseline ../lpvd-base/build/bench/lpvd-bench \
#       --new build/bench/lpvd-bench --rounds 5 -- --repeat 7 --warmup 2
#
# What is measured is the engine at REV; only bench/lpvd_bench.c is this
# checkout's (it uses nothing the engine gained after issue 11).
set -eu
if [ $# -ne 2 ]; then
  echo "usage: sh bench/build_baseline.sh REV DIR" >&2
  exit 2
fi
rev="$1"
dir="$2"
here="$(cd "$(dirname "$0")/.." && pwd)"
if [ ! -d "$dir" ]; then
  git -C "$here" worktree add --detach "$dir" "$rev"
fi
cp "$here/bench/lpvd_bench.c" "$dir/bench/lpvd_bench.c"
cmake -S "$dir" -B "$dir/build" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build "$dir/build" --target lpvd-bench -j "$(nproc)"
echo "build_baseline: $dir/build/bench/lpvd-bench (engine at $(git -C "$dir" rev-parse --short HEAD))"
