#!/usr/bin/env python3
"""sigterm_frame.py - SIGTERM while a GET_FRAME is in flight, then SIGTERM and SIGINT again (R7.4).

Issue 31, item 8: a GET_FRAME being rendered or encoded when SIGTERM came got
no reply, no SHUTTING_DOWN and no BYE, and a second SIGTERM or a SIGINT
killed the daemon at once. Client F has a 1024x1024 camera and has ticked;
its GET_FRAME (PNG: the render on the GL thread, then the encoding on a
worker) is timed once, then sent again and SIGTERM follows after
FRACTIONS[k] of that time (the render, the encoding, and just after the
send). 50 ms later a second SIGTERM and then a SIGINT arrive. Expected, each
time: F receives its GET_FRAME reply or ERROR SHUTTING_DOWN for that request,
then BYE (0x800F, request_id 0; an ERROR SHUTTING_DOWN with request_id 0
before it is tolerated) and EOF; the daemon logs the repeated signals and
exits 0 within 20 s.
"""

import signal
import sys
import time

from rel_common import harness, lc, ok, scene_session
from sigterm import drain_to_bye

SIDE = 1024
FRACTIONS = (0.0, 0.3, 0.8)


def reply_then_bye(frames, closed, rid):
    seq = [f for f in frames if isinstance(f, lc.Frame) and f.type != lc.VOLUME]
    if not seq or seq[0].rid != rid or seq[0].type not in (lc.GET_FRAME | lc.REPLY, lc.ERROR):
        return False, "first frame %r, expected the GET_FRAME reply or its ERROR" % (seq[0] if seq else None,)
    if seq[0].type == lc.ERROR and seq[0].err_name != "SHUTTING_DOWN":
        return False, "GET_FRAME answered %s" % seq[0].err_name
    what = "reply" if seq[0].type != lc.ERROR else "SHUTTING_DOWN"
    seq = seq[1:]
    if seq and seq[0].type == lc.ERROR and seq[0].rid == 0 and seq[0].err_name == "SHUTTING_DOWN":
        seq = seq[1:]
    if len(seq) != 1 or seq[0].type != lc.BYE_REPLY or seq[0].rid != 0:
        return False, "GET_FRAME %s, then %r, expected exactly BYE 0x800F request_id 0" % (what, seq)
    if not closed:
        return False, "no EOF after BYE"
    return True, "GET_FRAME %s, BYE, EOF" % what


def one(rep, lpvd, fraction):
    d = harness.Daemon(lpvd)
    d.start()
    try:
        f = scene_session(("unix", d.unix), timeout=300)
        ok(f.request(lc.CAMERA_SET, {"eye": [0, 1, 3.5], "target": [0, 1, 0], "width": SIDE, "height": SIDE}),
           lc.CAMERA_SET)
        ok(f.request(lc.TICK, {}, timeout=300), lc.TICK)
        t0 = time.monotonic()
        ok(f.request(lc.GET_FRAME, {"format": "png"}, timeout=300), lc.GET_FRAME)
        frame_s = time.monotonic() - t0
        rid = f.send(lc.GET_FRAME, {"format": "png"})
        time.sleep(fraction * frame_s)
        d.proc.send_signal(signal.SIGTERM)
        time.sleep(0.05)
        d.proc.send_signal(signal.SIGTERM)
        time.sleep(0.05)
        d.proc.send_signal(signal.SIGINT)
        frames, closed = drain_to_bye(f)
        good, why = reply_then_bye(frames, closed, rid)
        rep.check(good, "SIGTERM %.0f %% into a GET_FRAME of %.2f s: its answer, then BYE, then close" %
                  (100 * fraction, frame_s), why)
        try:
            rc = d.proc.wait(20)
        except Exception:
            rc = None
        rep.check(rc == 0, "a second SIGTERM and a SIGINT do not kill it: exit 0", "status %r" % (rc,))
    finally:
        d.kill()
    return d


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    args = ap.parse_args()
    rep = harness.Report("sigterm_frame")
    lpvd = harness.find_lpvd(args.lpvd)
    d = None
    for fraction in FRACTIONS:
        d = one(rep, lpvd, fraction)
    return rep.finish(d)


if __name__ == "__main__":
    sys.exit(main())
