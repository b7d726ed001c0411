#!/bin/sh
# The main job on a fresh Debian 12 machine: install what lpvd needs, build
# it, render the built-in Cornell box once (cornell.png, cornell-indirect.png)
# and then serve it: `lpvd serve` on the default Unix socket, printing how to
# connect. Stop it with Ctrl-C (SIGINT/SIGTERM end it cleanly).
set -eu
cd "$(dirname "$0")/.."
sh scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=RelWithDebInfo
cmake --build build -j "$(nproc)"
./build/server/lpvd render -o cornell.png --stats
./build/server/lpvd render --indirect-only -o cornell-indirect.png
echo "run.sh: wrote cornell.png and cornell-indirect.png; starting the daemon"
echo "run.sh: in another shell: ./build/clients/lpvctl/lpvctl tick + volume + query --point 0,0.01,0 --normal 0,1,0"
exec ./build/server/lpvd serve "$@"
