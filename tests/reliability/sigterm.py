#!/usr/bin/env python3
"""sigterm.py - SIGTERM while a TICK is in flight (R7.4).

Client T loads the test box at a 48^3 grid with 16 iterations (a tick of a
few hundred ms on llvmpipe) and measures one tick; client I only said HELLO
and idles; client S is subscribed to volumes. T sends a TICK, and a quarter
of a measured tick later the daemon gets SIGTERM. Expected: T receives its
TICK reply and then BYE (type 0x800F, request_id 0) and EOF; I and S receive
BYE and EOF (an ERROR SHUTTING_DOWN with request_id 0 before the BYE is
tolerated: SPEC section 4 lists both); the daemon exits 0 within 20 s.
"""

import signal
import socket
import sys
import time

from rel_common import harness, lc, hello, ok, scene_session

# the LPV's long tick (named: lpvd's default technique is auto since issue 30)
CONFIG = {"technique": "lpv", "grid": [48, 48, 48], "iterations": 16, "rsm_size": 128}


def drain_to_bye(c, timeout=20.0):
    """Frames until EOF; returns (frames, closed)."""
    frames = []
    t_end = time.monotonic() + timeout
    while time.monotonic() < t_end:
        try:
            frames.append(c.recv(timeout=max(0.1, t_end - time.monotonic())))
        except lc.Closed:
            return frames, True
        except socket.timeout:
            break
        except lc.Violation as e:
            frames.append(("violation", str(e)))
            break
    return frames, False


def bye_ok(frames, closed, want_first=None):
    """The sequence is [want_first?] [ERROR SHUTTING_DOWN rid 0]? BYE(0x800F, rid 0), then EOF."""
    seq = [f for f in frames if not (isinstance(f, lc.Frame) and f.type == lc.VOLUME)]
    if want_first is not None:
        if not seq or not isinstance(seq[0], lc.Frame) or seq[0].type != (want_first[0] | lc.REPLY) \
                or seq[0].rid != want_first[1]:
            return False, "first frame %r, expected the %s reply" % (seq[0] if seq else None,
                                                                     lc.type_name(want_first[0]))
        seq = seq[1:]
    if seq and isinstance(seq[0], lc.Frame) and seq[0].type == lc.ERROR and seq[0].rid == 0 \
            and seq[0].err_name == "SHUTTING_DOWN":
        seq = seq[1:]
    if len(seq) != 1 or not isinstance(seq[0], lc.Frame) or seq[0].type != lc.BYE_REPLY or seq[0].rid != 0:
        return False, "after that: %r, expected exactly BYE 0x800F request_id 0" % (seq,)
    if not closed:
        return False, "no EOF after BYE"
    return True, "BYE, EOF"


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    args = ap.parse_args()
    rep = harness.Report("sigterm")
    d = harness.Daemon(harness.find_lpvd(args.lpvd))
    d.start()
    try:
        ep = ("unix", d.unix)
        t = scene_session(ep, config=CONFIG)
        t0 = time.monotonic()
        ok(t.request(lc.TICK, {}, timeout=120), lc.TICK, "first TICK")
        tick_s = time.monotonic() - t0
        t0 = time.monotonic()
        ok(t.request(lc.TICK, {}, timeout=120), lc.TICK, "second TICK")
        tick_s = min(tick_s, time.monotonic() - t0)
        print("one tick at 48^3, 16 iterations: %.3f s" % tick_s)
        idle = lc.Conn(ep, timeout=10)
        hello(idle)
        sub = scene_session(ep, light={"id": "s", "type": "point", "intensity": 3.0, "position": [0, 1, 0]})
        ok(sub.request(lc.SUBSCRIBE, {"stream": "volume", "format": "fp16", "compression": "zstd"}), lc.SUBSCRIBE)

        rid = t.send(lc.TICK, {})
        time.sleep(max(0.01, tick_s / 4))
        t_sig = time.monotonic()
        d.proc.send_signal(signal.SIGTERM)
        frames, closed = drain_to_bye(t)
        good, why = bye_ok(frames, closed, (lc.TICK, rid))
        rep.check(good, "TICK in flight: its reply, then BYE (0x800F, request_id 0), then close", why)
        for name, c in (("idle client", idle), ("subscriber", sub)):
            fr, cl = drain_to_bye(c)
            g, w = bye_ok(fr, cl)
            rep.check(g, "%s: BYE then close" % name, w)
        try:
            rc = d.proc.wait(20)
        except Exception:
            rc = None
        dt = time.monotonic() - t_sig
        rep.check(rc == 0, "daemon exits 0 after SIGTERM", "status %r after %.2f s" % (rc, dt))
        try:
            lc.Conn(ep, timeout=2, connect_timeout=2).close()
            refused = False
        except OSError:
            refused = True
        rep.check(refused, "no longer accepting connections")
        return rep.finish(d)
    finally:
        d.kill()


if __name__ == "__main__":
    sys.exit(main())
