#!/bin/sh
# ctest entry (clients/CMakeLists.txt): start a fresh `lpvd serve` on a
# temporary Unix socket, run the Python client's self-test (or, with the
# 4th argument "example", examples/subscribe_and_shade.py) against it, stop
# the daemon. Exit 77 (ctest: skipped) when the daemon has no 'serve' command.
#   test_self_test.sh LPVD PYTHON3 CLIENT_DIR [example]
set -u
export PYTHONDONTWRITEBYTECODE=1  # no __pycache__ in the source tree
LPVD=$1
PY=$2
DIR=$3
MODE=${4:-self-test}

if [ ! -x "$LPVD" ]; then
    echo "SKIP: no daemon binary at $LPVD"
    exit 77
fi
if ! "$LPVD" serve --help >/dev/null 2>&1; then
    echo "SKIP: $LPVD has no 'serve' command yet"
    exit 77
fi

TMP=$(mktemp -d /tmp/lpvc-py.XXXXXX)
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
        cat "$TMP/daemon.log"
        exit 1
    fi
    sleep 0.1
done

if [ "$MODE" = example ]; then
    "$PY" "$DIR/examples/subscribe_and_shade.py" --address "$SOCK" --volumes 3
else
    "$PY" "$DIR/lpvd_client.py" --self-test "$SOCK"
fi
rc=$?
if [ $rc -ne 0 ]; then
    echo "--- daemon log ---"
    cat "$TMP/daemon.log"
fi
exit $rc
