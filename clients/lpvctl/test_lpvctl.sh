#!/bin/sh
# ctest entry (clients/CMakeLists.txt, run under tests/reliability/harness.py,
# which starts a fresh `lpvd serve` and passes its socket): drive the daemon
# with lpvctl through every message, checking exit statuses and the files
# written.
#   test_lpvctl.sh LPVCTL SOCKET
set -u
CTL=$1
SOCK=$2

TMP=$(mktemp -d /tmp/lpvctl-test.XXXXXX)
trap 'rm -rf "$TMP"' EXIT INT TERM

fail() {
    echo "FAIL: $*"
    exit 1
}

cd "$TMP" || exit 1
printf 'px,py,pz,nx,ny,nz\n0,0.01,0,0,1,0\n-0.9,1,0,1,0,0\n0.9,1,0,-1,0,0\n' >in.csv

# One session: every request message, in order.
"$CTL" --address "$SOCK" hello + tick + volume + volume -o v.bin + volume -o v16.json --format fp16 \
    + volume -o vq.bin --compression shq --error-bound 0.02 \
    + frame -o f.png + frame -o f.rgba --terms indirect + query --csv in.csv -o out.csv \
    + light-set probe --type point --intensity 5 --position 0,1.5,0 --color 1,1,1 + light-remove probe \
    + camera --eye 0,1,3.9 --target 0,1,0 --fov 40 --size 64x64 + knobs + config --iterations 4 --damping 0.25 --normal-bins off + tick + frame -o g.png \
    + stats + subscribe volume --delta -n 3 --tick -o s + unsubscribe volume + bye >session.txt 2>&1 ||
    { cat session.txt; fail "lpvctl session"; }
cat session.txt

[ -s v.bin ] && [ -s v.bin.json ] || fail "volume -o v.bin wrote nothing"
[ -s v16.json ] || fail "volume -o v16.json wrote nothing"
[ "$(wc -c <vq.bin)" -eq "$(wc -c <v.bin)" ] || fail "vq.bin (shq, decoded to fp32) is not v.bin's size"
grep -q '^  "error_bound": 0\.0[12]' vq.bin.json || fail "vq.bin.json does not carry the bound"
cmp -s vq.bin v.bin && fail "vq.bin is v.bin byte for byte: not quantised"
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
grep -q '^--damping .*number in 0\.\.1' session.txt || fail "knobs did not list the daemon's damping"
grep -q '"damping":0.25' session.txt || fail "config --damping 0.25 not in the effective config"
grep -q '"keyframe":false' session.txt || echo "note: no delta volume was streamed"

# Errors: a path load without --scene-root is refused (R4.3), exit status 1
# and the SPEC name on stderr; a non-object update is refused by the client.
if "$CTL" --address "$SOCK" load scene.glb 2>err.txt; then fail "load by path without --scene-root succeeded"; fi
grep -q PATH_REFUSED err.txt || { cat err.txt; fail "expected PATH_REFUSED"; }
if "$CTL" --address "$SOCK" update '[1]' 2>err.txt; then fail "update with a non-object succeeded"; fi
# A knob value outside the daemon's described range is refused before sending
# (usage error, exit 2), naming the knob.
"$CTL" --address "$SOCK" config --damping 7 2>err.txt
[ $? -eq 2 ] || fail "config --damping 7 must exit 2"
grep -q damping err.txt || { cat err.txt; fail "the refusal must name damping"; }
"$CTL" --address "$SOCK" nosuchcommand 2>/dev/null
[ $? -eq 2 ] || fail "an unknown command must exit 2"
"$CTL" --address "$TMP/nothing.sock" hello 2>/dev/null && fail "connecting to a missing socket succeeded"

echo "lpvctl session: ok"
exit 0
