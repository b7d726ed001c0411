#!/usr/bin/env python3
"""query_limits.py - QUERY_IRRADIANCE's largest count is advertised and can be sent (R4.7).

Issue 31, item 10: the count's bound was max_message / 24, which no request
can reach (its JSON makes it a few bytes over the message limit), and a count
whose reply would be over the per-client queue limit was computed in full and
only then refused. Two daemons with small limits:
  1. --max-message 1 MiB: HELLO's limits.max_query_points is the count whose
     request fits; a query of exactly that many points is answered in full,
     one more is refused BAD_FIELD naming count.
  2. --max-queue 1 MiB: limits.max_query_points is the count whose reply
     fits; that many are answered, one more gets LIMIT naming --max-queue
     before it is computed (the refusal says the reply "would be" over the
     limit; after an encoding it says it "is" over and was not sent), and
     the session goes on.
  3. The same daemon, technique probes (R5.15): GET_VOLUME content
     "visibility" at grid 8 (512 probes' records, 492 KB) is answered; at
     grid 12 (1728 probes, 1.66 MB of records) it gets LIMIT naming
     --max-queue before anything is read back, and the session goes on.
"""

import struct
import sys
import time

from rel_common import harness, lc, ok, scene_session

MIB = 1 << 20


def points(n):
    one = struct.pack("<6f", 0.0, 0.5, 0.0, 0.0, 1.0, 0.0)
    return one * n


def limit_of(c):
    rid = c.send(lc.HELLO, {"version": 1, "client": "query_limits"})
    f = c.recv_reply(rid, 10)
    return f.body["limits"]


def run(rep, lpvd, flag):
    with harness.Daemon(lpvd, extra=[flag, str(MIB)]) as d:
        c = lc.Conn(("unix", d.unix), timeout=120)
        lim = limit_of(c)
        n = lim.get("max_query_points")
        rep.check(isinstance(n, int) and n > 0, "%s: HELLO advertises limits.max_query_points" % flag, repr(n))
        if not isinstance(n, int):
            return d
        ok(c.request(lc.TICK, {}, timeout=120), lc.TICK)
        t0 = time.monotonic()
        f = c.request(lc.QUERY_IRRADIANCE, {"count": n}, points(n), timeout=120)
        dt_full = time.monotonic() - t0
        rep.check(f.type == (lc.QUERY_IRRADIANCE | lc.REPLY) and len(f.att) == 12 * n,
                  "%s: a query of max_query_points (%d) is answered in full" % (flag, n),
                  "%r, %d bytes in %.2f s" % (f.type, len(f.att), dt_full))
        t0 = time.monotonic()
        f = c.request(lc.QUERY_IRRADIANCE, {"count": n + 1}, points(n + 1), timeout=120)
        dt = time.monotonic() - t0
        if flag == "--max-message":
            rep.check(f.type == lc.ERROR and f.err_name == "BAD_FIELD" and "count" in str(f.body.get("message", "")),
                      "%s: one point more is refused BAD_FIELD naming count" % flag, repr(f))
        else:
            rep.check(f.type == lc.ERROR and f.err_name == "LIMIT" and "--max-queue" in str(f.body.get("message", "")),
                      "%s: one point more gets LIMIT naming --max-queue" % flag, repr(f))
            # the refusal after the encoding says "... is over ...: not sent"; the
            # one before any work says the reply "would be over"
            rep.check("would be over" in str(f.body.get("message", "")), "%s: refused before it is computed" % flag,
                      "%.3f s (the full query took %.3f s)" % (dt, dt_full))
        f = c.request(lc.QUERY_IRRADIANCE, {"count": 1}, points(1), timeout=60)
        rep.check(f.type == (lc.QUERY_IRRADIANCE | lc.REPLY), "%s: the session goes on" % flag, repr(f.type))
        if flag == "--max-queue":
            visibility(rep, c)
        c.close()
        return d


def visibility(rep, c):
    """R5.15: the probes' records over max_queue are refused before the read-back."""
    ask = {"format": "fp32", "compression": "none", "content": "visibility"}
    ok(c.request(lc.CONFIG, {"technique": "probes", "grid": 8, "cascades": 1, "probes_rays": 16}, timeout=60),
       lc.CONFIG)
    ok(c.request(lc.TICK, {}, timeout=120), lc.TICK)
    f = c.request(lc.GET_VOLUME, ask, timeout=120)
    vis = (f.body.get("volume") or {}).get("visibility", {}) if f.type == (lc.GET_VOLUME | lc.REPLY) else {}
    rep.check(vis.get("probes") == 512 and vis.get("raw_length") == 512 * vis.get("values_per_probe", 0) * 4,
              "--max-queue: 512 probes' visibility (under 1 MiB) is answered", repr((f.type, vis)))
    ok(c.request(lc.CONFIG, {"grid": 12}, timeout=60), lc.CONFIG)
    ok(c.request(lc.TICK, {}, timeout=120), lc.TICK)
    f = c.request(lc.GET_VOLUME, ask, timeout=120)
    msg = str(f.body.get("message", "")) if f.type == lc.ERROR else ""
    rep.check(f.type == lc.ERROR and f.err_name == "LIMIT" and "--max-queue" in msg and "not read back" in msg,
              "--max-queue: 1728 probes' visibility gets LIMIT naming --max-queue before the read-back", repr(f))
    f = c.request(lc.GET_VOLUME, {"format": "fp16"}, timeout=120)
    rep.check(f.type == (lc.GET_VOLUME | lc.REPLY), "--max-queue: the merged volume still comes", repr(f.type))


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    args = ap.parse_args()
    rep = harness.Report("query_limits")
    lpvd = harness.find_lpvd(args.lpvd)
    d = None
    for flag in ("--max-message", "--max-queue"):
        d = run(rep, lpvd, flag)
    return rep.finish(d)


if __name__ == "__main__":
    sys.exit(main())
