#!/usr/bin/env python3
"""stalled_headers.py - headers that declare a large frame and then send nothing do not hold the request memory (R7.5).

Issue 31, item 3: four authenticated sessions that each sent only the 24-byte
header of a frame declaring --max-message bytes held the whole
--max-request-memory, so every other client's frame larger than the read
buffer waited until the idle timeout. Scaled down: --max-message 16 MiB,
--max-request-memory 64 MiB, --idle-timeout 120. Four clients send only the
header of a STATS frame with a 16 MiB attachment; then a fifth sends a STATS
frame with a 1 MiB attachment. Expected: the fifth gets its reply once the
stalled reservations are cut to what arrived (SV_RESERVE_STALL_MS, 2 s), long
before the idle timeout (it is given 30 s); then each of the four sends the
rest of its frame and gets its reply too, and request_bytes returns to 0.
"""

import socket
import sys
import time

from rel_common import harness, lc, hello, ok

MIB = 1 << 20
STALLED = 4


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    args = ap.parse_args()
    rep = harness.Report("stalled_headers")
    extra = ["--max-message", str(16 * MIB), "--max-request-memory", str(64 * MIB)]
    with harness.Daemon(harness.find_lpvd(args.lpvd), idle_timeout=120, extra=extra) as d:
        ep = ("unix", d.unix)
        big = lc.encode_frame(lc.STATS, 7, {}, b"\0" * (16 * MIB - 64))
        stalled = []
        for _ in range(STALLED):
            c = lc.Conn(ep, timeout=60)
            hello(c)
            c.sock.sendall(big[:lc.HEADER_SIZE])
            stalled.append(c)
        time.sleep(0.3)
        e = lc.Conn(ep, timeout=60)
        hello(e)
        t0 = time.monotonic()
        try:
            f = e.request(lc.STATS, {}, b"\1" * MIB, timeout=30)
            got = f.type == (lc.STATS | lc.REPLY)
            why = "reply after %.1f s" % (time.monotonic() - t0)
        except (socket.timeout, TimeoutError) as ex:
            got, why = False, "no reply in 30 s (%s)" % ex
        rep.check(got, "a 1 MiB frame is read while %d stalled headers declare 16 MiB each" % STALLED, why)
        answered = 0
        for c in stalled:
            c.sock.sendall(big[lc.HEADER_SIZE:])
        for c in stalled:
            try:
                f = c.recv_reply(7, 60)
                answered += f.type == (lc.STATS | lc.REPLY)
            except Exception as ex:
                print("stalled client: %s" % ex)
        rep.check(answered == STALLED, "each stalled sender, once it sends the rest, is answered",
                  "%d of %d" % (answered, STALLED))
        st = ok(e.request(lc.STATS, {}, timeout=30), lc.STATS).body
        held = (st.get("queues") or {}).get("request_bytes")
        rep.check(held == 0, "request_bytes back to 0", repr(held))
        for c in stalled + [e]:
            c.close()
        rep.check(d.alive(), "daemon alive")
        return rep.finish(d)


if __name__ == "__main__":
    sys.exit(main())
