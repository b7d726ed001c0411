#!/bin/sh
# ctest entry (clients/CMakeLists.txt): start a fresh `lpvd serve` on a
# temporary Unix socket and drive it with lpvctl through every message,
# checking exit statuses and the files written. Exit 77 (ctest: skipped)
# when the daemon has no 'serve' command.
#   test_lpvctl.sh LPVD LPVCTL
set -u
LPVD=$1
CTL=$2

if [ ! -x "$LPVD" ]; then
    echo "SKIP: no daemon binary at $LPVD"
    exit 77
fi
if ! "$LPVD" serve --help >/dev/null 2>&1; then
    echo "SKIP: $LPVD has no 'serve' command yet"
    exit 77
fi

TMP=$(mktemp -d /tmp/lpvctl-test.XXXXXX)
SOCK=$TMP/lpvd.sock
"$LPVD" serve --socket "$SOCK" >"$TMP/daemon.log" 2>&1 &
PID=$!
cleanup() {
    kill -TERM "$PID" 2>/dev/null
    wait "$PID" 2>/dev/null
    rm -rf "$TMP"
}
trap cleanup EXIT INT TERM

i=0
while [ ! -S "$SOCK" ]; do
    if ! kill -0 "$PID" 2>/dev/null; then
        echo "FAIL: the daemon exited before creating its socket:"
        cat "$TMP/daemon.log"
        exit 1
    fi
    i=$((i + 1))
    if [ $i -gt 600 ]; then
        echo "FAIL: no socket at $SOCK after 60 s"
        exit 1
    fi
    sleep 0.1
done

fail() {
    echo "FAIL: $*"
    echo "--- daemon log ---"
    cat "$TMP/daemon.log"
    exit 1
}

cd "$TMP" || exit 1
printf 'px,py,pz,nx,ny,nz\n0,0.01,0,0,1,0\n-0.9,1,0,1,0,0\n0.9,1,0,-1,0,0\n' >in.csv

# One session: every request message, in order.
"$CTL" --address "$SOCK" hello + tick + volume + volume -o v.bin + volume -o v16.json --format fp16 \
    + frame -o f.png + frame -o f.rgba --terms indirect + query --csv in.csv -o out.csv \
    + light-set probe --type point --intensity 5 --position 0,1.5,0 --color 1,1,1 + light-remove probe \
    + camera --eye 0,1,3.9 --target 0,1,0 --fov 40 --size 64x64 + config --iterations 4 + tick + frame -o g.png \
    + stats + subscribe volume --delta -n 3 --tick -o s + unsubscribe volume + bye >session.txt 2>&1 ||
    { cat session.txt; fail "lpvctl session"; }
cat session.txt

[ -s v.bin ] && [ -s v.bin.json ] || fail "volume -o v.bin wrote nothing"
[ -s v16.json ] || fail "volume -o v16.json wrote nothing"
grep -q '"fp16"' v16.json || fail "v16.json does not say fp16"
cells=$(sed -n 's/^  "cells": \([0-9]*\),*$/\1/p' v.bin.json)
size=$(wc -c <v.bin)
[ -n "$cells" ] && [ "$size" -eq $((cells * 48)) ] || fail "v.bin is $size bytes for '$cells' cells"
head -c 8 f.png | od -An -tx1 | grep -q '89 50 4e 47 0d 0a 1a 0a' || fail "f.png is not a PNG"
[ -s f.rgba ] || fail "f.rgba is empty"
[ "$(wc -l <out.csv)" -eq 4 ] || fail "out.csv has $(wc -l <out.csv) lines, expected 4"
head -1 out.csv | grep -q '^E_r,E_g,E_b$' || fail "out.csv header"
[ -s s-1.bin ] || ls s-*.bin >/dev/null 2>&1 || fail "subscribe saved no volume"
[ "$(ls s-*.bin | wc -l)" -eq 3 ] || fail "subscribe saved $(ls s-*.bin | wc -l) volumes, expected 3"
grep -q '"keyframe":false' session.txt || echo "note: no delta volume was streamed"

# Errors: a path load without --scene-root is refused (R4.3), exit status 1
# and the SPEC name on stderr; a non-object update is refused by the client.
if "$CTL" --address "$SOCK" load scene.glb 2>err.txt; then fail "load by path without --scene-root succeeded"; fi
grep -q PATH_REFUSED err.txt || { cat err.txt; fail "expected PATH_REFUSED"; }
if "$CTL" --address "$SOCK" update '[1]' 2>err.txt; then fail "update with a non-object succeeded"; fi
"$CTL" --address "$SOCK" nosuchcommand 2>/dev/null
[ $? -eq 2 ] || fail "an unknown command must exit 2"
"$CTL" --address "$TMP/nothing.sock" hello 2>/dev/null && fail "connecting to a missing socket succeeded"

echo "lpvctl session: ok"
exit 0
