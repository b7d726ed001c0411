#!/usr/bin/env python3
"""serve_fairness.py - a cheap client's TICK while two clients run heavy ticks (issue 31, item 2).

Two clients, H1 and H2, each run a heavy configuration (by default the LPV at
grid 36, 3 cascades, 36 iterations: under --max-tick-cost, over a second of
GL time on a 2-core llvmpipe machine) and, in a loop, move their light and
TICK. A third, C, on the built-in box, ticks once, then sends a TICK with
nothing changed every 0.2 s. Reported: C's TICK round trips (p50, p99, max),
and what H1 and H2 got (ticks, LIMIT refusals, their tick times). The target
(issue 31): C answered within 1 s.

    python3 bench/serve_fairness.py --lpvd build/server/lpvd [--max-tick-ms 1000] [--vs OTHER_LPVD] [--seconds 30]
        [--heavy '{"technique": "iv", "iv_rays": 64, "iv_resolution": 64}']

With --vs the same run is made against a second binary (side by side, one
machine, one session: bench/build_baseline.sh builds an earlier revision).
"""

import argparse
import json
import os
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "tests", "reliability"))

from rel_common import harness, lc, hello, ok  # noqa: E402

HEAVY = {"technique": "lpv", "grid": [36, 36, 36]}
FRAME = None  # --heavy-frame WxH: the heavy clients also fetch a frame of that size each loop


def pct(v, p):
    s = sorted(v)
    return s[min(len(s) - 1, int(round(p / 100.0 * (len(s) - 1))))] if s else float("nan")


def heavy(ep, i, stop, out):
    c = lc.Conn(ep, timeout=600)
    hello(c)
    ok(c.request(lc.CONFIG, HEAVY, timeout=600), lc.CONFIG)
    if FRAME:
        ok(c.request(lc.CAMERA_SET, {"eye": [0.0, 1.0, 3.5], "target": [0.0, 1.0, 0.0], "width": FRAME[0],
                                     "height": FRAME[1]}, timeout=60), lc.CAMERA_SET)
    ticks, limits, ms = 0, 0, []
    k = 0
    while not stop.is_set():
        k += 1
        ok(c.request(lc.LIGHT_SET, {"id": "h", "type": "point", "intensity": 1.0,
                                    "position": [0.05 * (k % 7), 1.0, 0.1 * i]}, timeout=60), lc.LIGHT_SET)
        t0 = time.monotonic()
        f = c.request(lc.TICK, {}, timeout=600)
        if f.type == (lc.TICK | lc.REPLY) and FRAME:  # and a frame rendered for it (a render job)
            f = c.request(lc.GET_FRAME, {"format": "rgba8"}, timeout=600)
            f = f if f.type == lc.ERROR else lc.Frame(lc.TICK | lc.REPLY, f.rid, {}, b"", b"")
        if f.type == (lc.TICK | lc.REPLY):
            ticks += 1
            ms.append((time.monotonic() - t0) * 1000.0)
        elif f.type == lc.ERROR and f.err_name == "LIMIT":
            limits += 1
            time.sleep(0.05)
        else:
            raise RuntimeError(repr(f))
    out[i] = (ticks, limits, ms)
    c.close()


def run(lpvd, seconds, extra):
    with harness.Daemon(lpvd, quiet=True, extra=extra) as d:
        ep = ("unix", d.unix)
        c = lc.Conn(ep, timeout=600)
        hello(c)
        ok(c.request(lc.TICK, {}, timeout=600), lc.TICK)
        stop = threading.Event()
        out = {}
        hs = [threading.Thread(target=heavy, args=(ep, i, stop, out)) for i in range(2)]
        for t in hs:
            t.start()
        time.sleep(2.0)
        rtt = []
        t_end = time.monotonic() + seconds
        while time.monotonic() < t_end:
            t0 = time.monotonic()
            ok(c.request(lc.TICK, {}, timeout=600), lc.TICK)
            rtt.append((time.monotonic() - t0) * 1000.0)
            time.sleep(0.2)
        stop.set()
        for t in hs:
            t.join(600)
        c.close()
        return rtt, out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--lpvd", required=True)
    ap.add_argument("--vs", help="a second lpvd binary, run the same way after the first")
    ap.add_argument("--seconds", type=float, default=30.0)
    ap.add_argument("--heavy-frame", help="WxH: the heavy clients set a camera of that size and fetch a frame "
                                          "after each tick (a render job on the GL thread)")
    ap.add_argument("--heavy", help="the heavy clients' CONFIG as JSON (default %s)" % json.dumps(HEAVY))
    ap.add_argument("--max-tick-ms", action="append", default=[],
                    help="also run --lpvd with this --max-tick-ms (repeatable)")
    a = ap.parse_args()
    if a.heavy_frame:
        global FRAME
        FRAME = tuple(int(v) for v in a.heavy_frame.lower().split("x"))
    if a.heavy:
        HEAVY.clear()
        HEAVY.update(json.loads(a.heavy))
    rows = []
    runs = [("this", a.lpvd, [])] + [("this, --max-tick-ms %s" % m, a.lpvd, ["--max-tick-ms", m])
                                      for m in a.max_tick_ms] + ([("vs", a.vs, [])] if a.vs else [])
    for name, binary, extra in runs:
        rtt, out = run(os.path.abspath(binary), a.seconds, extra)
        hticks = sum(v[0] for v in out.values())
        hlim = sum(v[1] for v in out.values())
        hms = [m for v in out.values() for m in v[2]]
        rows.append((name, binary, len(rtt), pct(rtt, 50), pct(rtt, 99), max(rtt) if rtt else float("nan"),
                     hticks, hlim, pct(hms, 50)))
    print("| binary | C's TICKs | p50 ms | p99 ms | max ms | heavy ticks | heavy LIMITs | heavy tick p50 ms |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for r in rows:
        print("| %s (`%s`) | %d | %.0f | %.0f | %.0f | %d | %d | %.0f |" % r)
    return 0


if __name__ == "__main__":
    sys.exit(main())
