#!/usr/bin/env python3
"""sighup.py - SIGHUP does not end the daemon (issue 14, docs/server.md "Signals").

Without a handler SIGHUP's default action kills the process: no BYE, and the
socket file stays behind. Expected: after SIGHUP (twice) the daemon still
answers a session opened before it (TICK) and accepts a new one; then
SIGTERM ends it as R7.4 says (BYE, exit 0, socket file removed).
"""

import os
import signal
import sys
import time

from rel_common import harness, lc, hello, ok, scene_session


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    args = ap.parse_args()
    rep = harness.Report("sighup")
    d = harness.Daemon(harness.find_lpvd(args.lpvd))
    d.start()
    try:
        ep = ("unix", d.unix)
        a = scene_session(ep)
        ok(a.request(lc.TICK, {}, timeout=120), lc.TICK, "TICK before SIGHUP")
        for _ in range(2):
            d.proc.send_signal(signal.SIGHUP)
            time.sleep(0.3)
        rep.check(d.proc.poll() is None, "the daemon is alive after two SIGHUPs", "status %r" % d.proc.poll())
        ok(a.request(lc.TICK, {}, timeout=120), lc.TICK, "TICK after SIGHUP")
        rep.check(True, "a session opened before SIGHUP still ticks")
        b = lc.Conn(ep, timeout=10)
        hello(b)
        rep.check(True, "a new connection says HELLO after SIGHUP")
        d.proc.send_signal(signal.SIGTERM)
        got_bye = False
        t_end = time.monotonic() + 20
        while time.monotonic() < t_end:
            try:
                f = b.recv(timeout=max(0.1, t_end - time.monotonic()))
            except lc.Closed:
                break
            if isinstance(f, lc.Frame) and f.type == lc.BYE_REPLY:
                got_bye = True
        rep.check(got_bye, "SIGTERM afterwards: BYE")
        try:
            rc = d.proc.wait(20)
        except Exception:
            rc = None
        rep.check(rc == 0, "then exit 0", "status %r" % rc)
        rep.check(not os.path.exists(d.unix), "and the socket file is removed", d.unix)
        return rep.finish(d)
    finally:
        d.kill()


if __name__ == "__main__":
    sys.exit(main())
