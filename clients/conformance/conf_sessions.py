"""conf_sessions.py - conformance cases: sessions with identical inputs share nothing they should
not (R7.1, R7.2)."""

import os
import random
import socket
import time

from conf_wire import GET_VOLUME, LIGHT_SET, REPLY, STATS, TICK
from conf_core import case, check, expect_reply


@case("R7.1 R7.2 R3.3", "two sessions with identical inputs: own revisions, equal volumes, no leaking updates")
def c_sessions(ctx):
    inten = 6.0 + random.random()
    lt = {"id": "share-%d" % os.getpid(), "type": "point", "intensity": inten, "position": [0.2, 1.4, 0.1]}
    a, _, _ = ctx.scene_session(tick=False)
    for k in (1.0, 2.0, 1.0):
        l2 = dict(lt)
        l2["intensity"] = inten * k
        ra = expect_reply(a.request(LIGHT_SET, l2), LIGHT_SET)
    b, _, _ = ctx.scene_session(tick=False)
    rb = expect_reply(b.request(LIGHT_SET, lt), LIGHT_SET)
    # Both TICKs go out at once, here and below, and neither session sits
    # idle while the other's tick runs: this suite's daemon has a 4 s idle
    # timeout, and under ASan on two busy cores one session was sent BYE
    # while the other waited (_tick_both).
    ta, tb = _tick_both(ctx, a, b)
    check(ta.body.get("revision") == ra.body.get("revision"), "A's TICK revision %r, its last update %r"
          % (ta.body.get("revision"), ra.body.get("revision")))
    check(tb.body.get("revision") == rb.body.get("revision"), "B's TICK revision %r, its last update %r"
          % (tb.body.get("revision"), rb.body.get("revision")))
    check(ra.body.get("revision") != rb.body.get("revision"), "A and B have the same revision %r after different "
          "numbers of updates" % ra.body.get("revision"))
    va = expect_reply(a.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    vb = expect_reply(b.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    check(va.att == vb.att, "identical inputs gave different volumes")
    check(va.body.get("revision") == ra.body.get("revision") and vb.body.get("revision") == rb.body.get("revision"),
          "volume revisions %r/%r, expected each session's own %r/%r" % (va.body.get("revision"),
                                                                          vb.body.get("revision"),
                                                                          ra.body.get("revision"),
                                                                          rb.body.get("revision")))
    l3 = dict(lt)
    l3["intensity"] = inten * 4
    expect_reply(b.request(LIGHT_SET, l3), LIGHT_SET)
    _tick_both(ctx, b, a)
    va2 = expect_reply(a.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    vb2 = expect_reply(b.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    check(va2.att == va.att, "B's LIGHT_SET changed A's volume (R7.1)")
    check(vb2.att != vb.att, "B's LIGHT_SET did not change B's volume")
    s = c_stats_body(ctx)
    return "revisions A %r, B %r; equal volumes; B's update stayed in B (STATS worlds %r)" % (
        ra.body.get("revision"), rb.body.get("revision"), s.get("worlds"))


def _tick_both(ctx, a, b):
    """TICK on a and b, both sent at once; while one's tick still runs, the
    other, already answered, sends STATS about every second, so that neither
    session is idle (R4.9) however long a loaded machine takes (a world's
    first tick builds its GL programs). Their TICK replies."""
    pending = {a: a.send(TICK, {}), b: b.send(TICK, {})}
    replies = {}
    deadline = time.monotonic() + ctx.tick_timeout
    while pending:
        for c in list(pending):
            try:
                replies[c] = expect_reply(c.recv_reply(pending[c], 1.0), TICK, pending[c])
                del pending[c]
            except socket.timeout:
                pass
        if pending:
            for c in replies:
                expect_reply(c.request(STATS, {}), STATS)
        check(time.monotonic() < deadline, "no TICK reply within %g s" % ctx.tick_timeout)
    return replies[a], replies[b]


def c_stats_body(ctx):
    try:
        c = ctx.session()
        f = c.request(STATS, {})
        return f.body if f.type == STATS | REPLY else {}
    except Exception:
        return {}
