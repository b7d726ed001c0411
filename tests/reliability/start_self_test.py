#!/usr/bin/env python3
"""start_self_test.py - lpvd serve runs its passes once before it listens (issue 31).

A daemon that must run for months should find out at start, not at each
client's first TICK, whether its GL can run lpvd's passes. `lpvd serve` ticks
the built-in box at the default settings and renders a small frame, in a GL
context of its own that it then destroys, before it listens:
  1. a normal start: no warning in the log, STATS counts no tick (the
     self-test is not a client's), and the first client ticks;
  2. a GL whose memory cannot hold the defaults (LPVD_MEMORY_BUDGET_MB=20):
     the daemon still starts (clients may ask for less), and its log warns
     at start that the defaults do not fit, naming the budget; a TICK at the
     defaults then gets LIMIT.
(A GL that cannot build the passes fails the start with the reason; no
driver at hand fails that way, so it is not exercised here.)
"""

import os
import sys

from rel_common import harness, lc, hello, ok


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    args = ap.parse_args()
    rep = harness.Report("start_self_test")
    lpvd = harness.find_lpvd(args.lpvd)
    with harness.Daemon(lpvd) as d:
        log = d.log_tail()
        rep.check("warning" not in log, "a normal start logs no warning", log[-400:])
        c = lc.Conn(("unix", d.unix), timeout=120)
        hello(c)
        st = ok(c.request(lc.STATS, {}), lc.STATS).body
        rep.check(st.get("ticks_computed") == 0, "STATS counts no tick before a client's",
                  repr(st.get("ticks_computed")))
        f = c.request(lc.TICK, {}, timeout=120)
        rep.check(f.type == (lc.TICK | lc.REPLY), "the first client ticks", repr(f)[:200])
        c.close()
        rep.check(d.alive(), "daemon alive")
    env = dict(os.environ)
    env["LPVD_MEMORY_BUDGET_MB"] = "20"
    with harness.Daemon(lpvd, env=env) as d:
        log = d.log_tail()
        rep.check("does not fit this GL's memory" in log and "LPVD_MEMORY_BUDGET_MB=20" in log,
                  "with a 20 MB budget the start warns that the defaults do not fit, naming it", log[-600:])
        c = lc.Conn(("unix", d.unix), timeout=120)
        hello(c)
        f = c.request(lc.TICK, {}, timeout=120)
        rep.check(f.type == lc.ERROR and f.err_name == "LIMIT", "a TICK at the defaults gets LIMIT", repr(f)[:300])
        c.close()
        rep.check(d.alive(), "daemon alive")
        return rep.finish(d)


if __name__ == "__main__":
    sys.exit(main())
