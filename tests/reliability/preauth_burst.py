#!/usr/bin/env python3
"""preauth_burst.py - clients that say HELLO are not evicted by a burst or a flood of connections (R4.1a).

Issue 31, item 4: past --max-preauth (16) the oldest connection waiting for
HELLO was closed at once, so 50 clients connecting together lost 14-16 to
LIMIT, and a connect flood without a token from one process evicted 7 % of
legitimate HELLOs (23 % of those sent 50 ms after connecting). Against one
daemon on its Unix socket at the default limits:
  1. burst: 50 threads connect at once and each says HELLO: all 50 get in.
  2. flood: another process opens connections without a word as fast as it
     can (keeping the newest 200 open) while this one makes 40 clients, each
     saying HELLO 50 ms after connecting: all 40 get in (the flood's own
     connections are the ones evicted: its process holds the most).
"""

import os
import subprocess
import sys
import threading
import time

from rel_common import harness, lc, hello

FLOOD = r"""
import socket, sys, time
path, stop_at = sys.argv[1], time.monotonic() + float(sys.argv[2])
held = []
n = 0
while time.monotonic() < stop_at:
    try:
        s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        s.connect(path)
        held.append(s)
        n += 1
        if len(held) > 200:
            held.pop(0).close()
    except OSError:
        time.sleep(0.001)
print(n)
"""


def connect(ep, deadline):
    """A connection, retried while the listen queue is full (EAGAIN on a Unix socket: the kernel's answer to
    a flood, before lpvd sees the client; what is tested here is what lpvd does once it has)."""
    while True:
        try:
            return lc.Conn(ep, timeout=30)
        except BlockingIOError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.01)


def try_hello(ep, delay, results, i):
    try:
        c = connect(ep, time.monotonic() + 20)
        if delay:
            time.sleep(delay)
        hello(c)
        results[i] = "ok"
        c.close()
    except Exception as e:
        results[i] = repr(e)[:200]


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    args = ap.parse_args()
    rep = harness.Report("preauth_burst")
    with harness.Daemon(harness.find_lpvd(args.lpvd), extra=["--max-clients", "128"]) as d:
        ep = ("unix", d.unix)
        results = [None] * 50
        threads = [threading.Thread(target=try_hello, args=(ep, 0.0, results, i)) for i in range(50)]
        for t in threads:
            t.start()
        for t in threads:
            t.join(60)
        bad = [r for r in results if r != "ok"]
        rep.check(not bad, "50 clients connecting at once all get in", "%d refused: %s" % (len(bad), bad[:2]))

        flood = subprocess.Popen([sys.executable, "-c", FLOOD, d.unix, "8"], stdout=subprocess.PIPE, text=True)
        time.sleep(1.0)
        results = [None] * 40
        threads = []
        for i in range(40):
            t = threading.Thread(target=try_hello, args=(ep, 0.05, results, i))
            t.start()
            threads.append(t)
            time.sleep(0.1)
        for t in threads:
            t.join(60)
        out, _ = flood.communicate(timeout=60)
        bad = [r for r in results if r != "ok"]
        rep.check(not bad, "40 clients saying HELLO 50 ms after connecting, during another process's connect flood "
                  "(%s connections), all get in" % out.strip(), "%d evicted: %s" % (len(bad), bad[:2]))
        rep.check(d.alive(), "daemon alive")
        return rep.finish(d)


if __name__ == "__main__":
    sys.exit(main())
