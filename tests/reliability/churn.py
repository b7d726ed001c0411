#!/usr/bin/env python3
"""churn.py - 1000 connect / HELLO / disconnect cycles leak neither descriptors nor memory.

After 100 warm-up cycles the daemon's open descriptors (/proc/PID/fd) and
VmRSS are recorded; then 1000 cycles in four styles (HELLO + BYE; HELLO then
close; HELLO sent and closed before the reply is read; connect and close
without a byte), with a client holding a loaded scene alive throughout.
Bounds: descriptors equal to the baseline +-2; VmRSS growth < 8 MiB
(< 24 MiB for an ASan build, whose allocator keeps a quarantine); the
scene client still served.
"""

import sys
import time

from rel_common import harness, lc, hello, ok, scene_session, settle

CYCLES = 1000
WARMUP = 100


def cycle(ep, i):
    c = lc.Conn(ep, timeout=10)
    try:
        style = i % 4
        if style == 0:
            hello(c)
            rid = c.send(lc.BYE, {})
            f = c.recv_reply(rid)
            if f.type != lc.BYE_REPLY:
                raise RuntimeError("BYE reply %r" % f)
        elif style == 1:
            hello(c)
        elif style == 2:
            c.send(lc.HELLO, {"version": 1})
        # style 3: connect and close
    finally:
        c.close()


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    args = ap.parse_args()
    rep = harness.Report("churn")
    with harness.Daemon(harness.find_lpvd(args.lpvd)) as d:
        ep = ("unix", d.unix)
        keeper = scene_session(ep)
        ok(keeper.request(lc.TICK, {}, timeout=60), lc.TICK)
        errors = []
        for i in range(WARMUP):
            try:
                cycle(ep, i)
            except Exception as e:
                errors.append("warm-up %d: %s" % (i, e))
        time.sleep(0.5)
        fd0 = d.fd_count()
        rss0 = d.rss_kib()
        t0 = time.monotonic()
        for i in range(CYCLES):
            try:
                cycle(ep, i)
            except Exception as e:
                errors.append("cycle %d: %s" % (i, e))
                if len(errors) > 20:
                    break
        dt = time.monotonic() - t0
        fd1 = settle(d.fd_count, fd0, 2, timeout=5)
        rss1 = d.rss_kib()
        bound = 24 if d.asan else 8
        rep.check(not errors, "%d cycles without error" % CYCLES, "; ".join(errors[:3]) if errors else
                  "%.2f s, %.0f cycles/s" % (dt, CYCLES / dt))
        rep.check(abs(fd1 - fd0) <= 2, "open descriptors unchanged (+-2)", "%d before, %d after" % (fd0, fd1))
        rep.check(rss1 - rss0 < bound * 1024, "VmRSS growth < %d MiB after warm-up" % bound,
                  "%.2f MiB -> %.2f MiB (%+.2f MiB)" % (rss0 / 1024.0, rss1 / 1024.0, (rss1 - rss0) / 1024.0))
        try:
            ok(keeper.request(lc.TICK, {}, timeout=60), lc.TICK)
            v = ok(keeper.request(lc.GET_VOLUME, {"format": "fp32", "compression": "none"}), lc.GET_VOLUME)
            rep.check(len(v.att) == 16 ** 3 * 48, "the long-lived session still ticks and answers",
                      "%d bytes" % len(v.att))
        except Exception as e:
            rep.check(False, "the long-lived session still ticks and answers", str(e))
        st = keeper.request(lc.STATS, {})
        if st.type == (lc.STATS | lc.REPLY):
            cl = st.body.get("clients")
            if isinstance(cl, int) and not isinstance(cl, bool):
                rep.check(cl == 1, "STATS counts only the live client", "clients %r" % cl)
            else:
                print("note: STATS clients is %r (not an integer; not checked)" % (cl,))
        keeper.close()
        rep.check(d.alive(), "daemon alive")
        return rep.finish(d)


if __name__ == "__main__":
    sys.exit(main())
