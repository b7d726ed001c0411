"""rel_common.py - small helpers shared by the reliability scripts (tests/reliability/*.py)."""

import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(HERE)), "clients", "conformance"))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(HERE)), "clients", "python"))

import harness  # noqa: E402
import lpvd_conformance as lc  # noqa: E402


def hello(conn, token=None, timeout=10.0):
    body = {"version": 1, "client": "reliability"}
    if token:
        body["token"] = token
    rid = conn.send(lc.HELLO, body)
    f = conn.recv_reply(rid, timeout)
    if f.type != (lc.HELLO | lc.REPLY):
        raise RuntimeError("HELLO failed: %r" % f)
    return f


def ok(f, req_type, what=""):
    if f.type != (req_type | lc.REPLY):
        raise RuntimeError("%s%s failed: %r" % (what + ": " if what else "", lc.type_name(req_type), f))
    return f


def scene_session(ep, token=None, config=None, light=None, timeout=60.0, rcvbuf=None):
    """HELLO + SCENE_LOAD (test box) + CONFIG (+ LIGHT_SET)."""
    c = lc.Conn(ep, timeout=timeout, rcvbuf=rcvbuf)
    hello(c, token)
    ok(c.request(lc.SCENE_LOAD, {}, lc.box_scene_glb(), timeout=timeout), lc.SCENE_LOAD)
    ok(c.request(lc.CONFIG, dict(config or lc.SMALL_CONFIG), timeout=timeout), lc.CONFIG)
    if light:
        ok(c.request(lc.LIGHT_SET, light, timeout=timeout), lc.LIGHT_SET)
    return c


def shq_subscribe(ep, config, light, bound):
    """A scene session (test box, config, light) subscribed to shq deltas at bound (SPEC R5.16)."""
    c = scene_session(ep, config=config, light=dict(light), timeout=120)
    ok(c.request(lc.SUBSCRIBE, {"stream": "volume", "compression": "shq", "error_bound": bound, "delta": True},
                 timeout=60), lc.SUBSCRIBE)
    return c


def shq_tick(c, before, bound):
    """TICK on an shq_subscribe session, its VOLUME decoded against before
    (the held bytes, None for none) and ACKed, and GET_VOLUME fp32 of that
    tick. Returns (VOLUME, held bytes, exact bytes, cells, the worst D / M
    of the held volume, the cells of before past the bound or None)."""
    import lpvd_volume as lv  # the Python client's decoder
    ok(c.request(lc.TICK, {}, timeout=300), lc.TICK)
    v = c.recv_stream(lc.VOLUME, timeout=60)
    held = lv.shq_decode(v.att, v.body, before)
    c.send(lc.ACK, {"stream": "volume", "tick": v.body["tick"]})
    exact = bytes(ok(c.request(lc.GET_VOLUME, {"format": "fp32", "compression": "none"}, timeout=120),
                     lc.GET_VOLUME).att)
    cells, _ = lv.shq_cells(v.body)
    D, M = lv.shq_distances(held, exact, cells)
    worst = max((dd / mm for dd, mm in zip(D, M) if mm > 0), default=0.0)
    moved = None
    if before is not None:
        Db, Mb = lv.shq_distances(before, exact, cells)
        moved = sum(1 for dd, mm in zip(Db, Mb) if dd > bound * mm)
    return v, held, exact, cells, worst, moved


def percentile(vals, p):
    if not vals:
        return float("nan")
    s = sorted(vals)
    k = min(len(s) - 1, max(0, int(round(p / 100.0 * (len(s) - 1)))))
    return s[k]


def settle(fn, target, tolerance, timeout=5.0):
    """Polls fn() until |fn() - target| <= tolerance or timeout; returns the last value."""
    t_end = time.monotonic() + timeout
    v = fn()
    while abs(v - target) > tolerance and time.monotonic() < t_end:
        time.sleep(0.1)
        v = fn()
    return v
