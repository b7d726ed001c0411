"""rel_common.py - small helpers shared by the reliability scripts (tests/reliability/*.py)."""

import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(HERE)), "clients", "conformance"))

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
