"""conf_queries.py - conformance cases: QUERY_IRRADIANCE (R4.7), and settings at the advertised
limits (R7.6)."""

import json
import math
import random
import struct

from conf_wire import CONFIG, ERROR, GET_VOLUME, QUERY_IRRADIANCE, TICK
from conf_payloads import f32_list
from conf_core import Fail, case, check, expect_error, expect_reply, is_finite_list, unique_light


# ---------------------------------------------------------------------------
# Cases: irradiance queries


def _points(n, seed=1):
    rnd = random.Random(seed)
    pts = []
    for i in range(n):
        kind = i % 3
        if kind == 0:   # floor, facing up
            p, nrm = (rnd.uniform(-0.9, 0.9), 0.05, rnd.uniform(-0.9, 0.9)), (0, 1, 0)
        elif kind == 1:  # left wall, facing +x
            p, nrm = (-0.95, rnd.uniform(0.1, 1.9), rnd.uniform(-0.9, 0.9)), (1, 0, 0)
        else:            # mid-air, random normal
            v = [rnd.gauss(0, 1) for _ in range(3)]
            ln = math.sqrt(sum(x * x for x in v)) or 1
            p, nrm = (rnd.uniform(-0.8, 0.8), rnd.uniform(0.2, 1.8), rnd.uniform(-0.8, 0.8)), tuple(x / ln for x in v)
        pts.append(p + nrm)
    return b"".join(struct.pack("<6f", *q) for q in pts)


@case("R4.7", "QUERY_IRRADIANCE before any tick gets NOT_READY")
def c_query_not_ready(ctx):
    c, _, _ = ctx.scene_session(tick=False, light=unique_light("nr"))
    rid = c.send(QUERY_IRRADIANCE, {"count": 4}, _points(4))
    expect_error(c.recv_reply(rid), "NOT_READY", rid)
    rid = c.send(GET_VOLUME, {})
    expect_error(c.recv_reply(rid), "NOT_READY", rid)
    return "QUERY_IRRADIANCE and GET_VOLUME: NOT_READY"


@case("R4.7", "QUERY_IRRADIANCE with a wrong attachment size gets BAD_FIELD; stays open")
def c_query_bad_size(ctx):
    c, _, _ = ctx.scene_session()
    for count, att in ((4, _points(4)[:-1]), (4, b""), (4, _points(5)), (1, b"\0" * 12), (0, b"\0" * 24),
                       (-1, b""), (2.5, _points(2))):
        rid = c.send(QUERY_IRRADIANCE, {"count": count}, att)
        f = c.recv_reply(rid)
        if count == 0 and not att:
            continue
        try:
            expect_error(f, "BAD_FIELD", rid)
        except Fail as e:
            raise Fail("count %r with %d bytes: %s" % (count, len(att), e))
    ctx.ping(c)
    return "7 mismatches refused"


@case("R7.6 R4.6a", "settings at the advertised limits either tick or are refused with LIMIT, never INTERNAL")
def c_limits_tick_or_limit(ctx):
    c, _, _ = ctx.scene_session()
    mg = ctx.max_grid()
    if not mg:
        return "no max_grid advertised: skipped"
    seen = []
    for body in ({"technique": "lpv", "grid": [mg] * 3, "cascades": 1, "far_field": False, "normal_bins": False,
                  "iterations": 1},
                 {"technique": "lpv", "grid": [mg] * 3, "cascades": 4, "iterations": 1}):
        f = c.request(CONFIG, body)
        if f.type == ERROR:
            expect_error(f, "LIMIT")
            seen.append("CONFIG LIMIT")
            continue
        t = c.request(TICK, {}, timeout=ctx.tick_timeout)
        if t.type == ERROR:
            if t.err_name != "LIMIT":
                raise Fail("CONFIG %s accepted, then TICK: %s (expected a reply or LIMIT)" % (json.dumps(body), t))
            seen.append("TICK LIMIT")
        else:
            seen.append("ticked")
    ctx.ping(c)
    return "max_grid %d: %s" % (mg, ", ".join(seen))


@case("R4.7", "QUERY_IRRADIANCE over HELLO's limits.max_query_points is refused before its attachment is read")
def c_query_over_max(ctx):
    c, _, _ = ctx.scene_session()
    n = (ctx.limits or {}).get("max_query_points")
    if not isinstance(n, int) or isinstance(n, bool) or n < 1:
        raise Fail("HELLO limits.max_query_points is %r, expected a positive integer" % (n,))
    rid = c.send(QUERY_IRRADIANCE, {"count": n + 1}, _points(1))
    f = c.recv_reply(rid)
    if f.type != ERROR or f.err_name not in ("BAD_FIELD", "LIMIT") or "count" not in json.dumps(f.body):
        raise Fail("count max_query_points + 1 = %d: expected BAD_FIELD or LIMIT naming count, got %r" % (n + 1, f))
    ctx.ping(c)
    return "max_query_points %d; %d refused (%s)" % (n, n + 1, f.err_name)


@case("R4.7 R3.3", "QUERY_IRRADIANCE after a tick: count x 12 bytes of finite, non-negative irradiance")
def c_query_ok(ctx):
    c, _, t = ctx.scene_session()
    n = 300
    rid = c.send(QUERY_IRRADIANCE, {"count": n}, _points(n))
    f = c.recv_reply(rid, timeout=ctx.tick_timeout)
    expect_reply(f, QUERY_IRRADIANCE, rid)
    b = f.body
    check(b.get("count") == n, "reply count %r, expected %d" % (b.get("count"), n))
    check(isinstance(b.get("revision"), int), "reply without integer revision")
    check(b.get("tick") == t.body.get("tick"), "reply tick %r, expected the latest tick %r"
          % (b.get("tick"), t.body.get("tick")))
    check(len(f.att) == n * 12, "attachment %d bytes, expected %d" % (len(f.att), n * 12))
    vals = f32_list(f.att)
    check(is_finite_list(vals), "non-finite irradiance values")
    check(min(vals) >= 0.0, "negative irradiance %g" % min(vals))
    floor = [vals[i * 3:i * 3 + 3] for i in range(0, n, 3)]
    check(sum(sum(e) for e in floor) > 0.0, "all floor points have zero irradiance in a lit box")
    # the red wall bleeds red onto the floor near it; not asserted (LPV is coarse), only reported
    return "%d points, max %.4g W/m^2" % (n, max(vals))


@case("R4.7", "QUERY_IRRADIANCE answers are deterministic for the same tick")
def c_query_repeat(ctx):
    c, _, _ = ctx.scene_session()
    pts = _points(30, seed=3)
    a = expect_reply(c.request(QUERY_IRRADIANCE, {"count": 30}, pts), QUERY_IRRADIANCE)
    b = expect_reply(c.request(QUERY_IRRADIANCE, {"count": 30}, pts), QUERY_IRRADIANCE)
    check(a.att == b.att, "two queries of the same points on the same tick differ")
    return "identical"
