#!/bin/sh
# The main job on a fresh Debian 12 machine: install what lpvd needs, build
# it, and render the built-in Cornell box to cornell.png (and its indirect
# light alone to cornell-indirect.png), printing the per-stage stats.
set -eu
cd "$(dirname "$0")/.."
sh scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=RelWithDebInfo
cmake --build build -j "$(nproc)"
./build/server/lpvd render -o cornell.png --stats
./build/server/lpvd render --indirect-only -o cornell-indirect.png
echo "run.sh: wrote cornell.png and cornell-indirect.png"
