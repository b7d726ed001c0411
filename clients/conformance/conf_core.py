"""conf_core.py - what every conformance case is built on: the case registry (@case, CASES; the
order cases are registered in is the order they run and are listed in), the verdict exceptions
(Fail, Skip), the reply checks (check, expect_reply, expect_error, R3.4's error shape) and Ctx,
the run's endpoints, options and session helpers."""

import math
import os
import random
import socket

from conf_wire import (
    CONFIG, DEFAULT_MAX_BODY, ERROR, ERROR_NAMES, HELLO, LIGHT_SET, REPLY, SCENE_LOAD, STATS, TICK, Closed, Conn,
    parse_endpoint, type_name)
from conf_payloads import SMALL_CONFIG, box_scene_glb


# ---------------------------------------------------------------------------
# Case machinery


class Fail(Exception):
    pass


class Skip(Exception):
    pass


def check(cond, msg):
    if not cond:
        raise Fail(msg)


CASES = []


def case(reqs, title, needs=()):
    def deco(fn):
        CASES.append({"reqs": reqs.split(), "title": title, "fn": fn, "needs": needs})
        return fn
    return deco


def check_error_shape(f):
    """R3.4: {"code": int, "name": str, "message": str}, name matching code."""
    b = f.body
    check(isinstance(b.get("code"), int) and not isinstance(b.get("code"), bool),
          "R3.4: ERROR body has no integer \"code\": %r" % (b,))
    check(isinstance(b.get("name"), str), "R3.4: ERROR body has no string \"name\": %r" % (b,))
    check(isinstance(b.get("message"), str), "R3.4: ERROR body has no string \"message\": %r" % (b,))
    check(ERROR_NAMES.get(b["code"]) == b["name"],
          "R3.4: ERROR code %r does not match name %r (table: %r)" % (b["code"], b["name"],
                                                                      ERROR_NAMES.get(b["code"])))


def expect_error(f, name, rid=None, field=None):
    check(f.type == ERROR, "expected ERROR %s, got %r" % (name, f))
    check_error_shape(f)
    check(f.body["name"] == name, "expected ERROR %s, got ERROR %s (%s)" % (name, f.body["name"],
                                                                           f.body.get("message")))
    if rid is not None:
        check(f.rid == rid, "ERROR %s carries request_id %d, expected %d" % (name, f.rid, rid))
    if field is not None:
        check(field in f.body["message"], "ERROR %s message %r does not name the field %r (R2.9)"
              % (name, f.body["message"], field))


def expect_reply(f, req_type, rid=None, what=None):
    want = req_type | REPLY
    if f.type == ERROR:
        raise Fail("%s: expected %s, got ERROR %s: %s" % (what or type_name(req_type), type_name(want),
                                                          f.body.get("name"), f.body.get("message")))
    check(f.type == want, "%s: expected reply type 0x%04X, got %r" % (what or type_name(req_type), want, f))
    if rid is not None:
        check(f.rid == rid, "reply request_id %d, expected %d (R3.1)" % (f.rid, rid))
    return f


def is_finite_list(vals):
    return all(math.isfinite(v) for v in vals)


class Ctx:
    def __init__(self, args):
        self.args = args
        self.endpoints = []
        if args.unix:
            self.endpoints.append(("unix", args.unix))
        if args.tcp:
            self.endpoints.append(parse_endpoint(args.tcp if ":" in args.tcp else "127.0.0.1:" + args.tcp))
            if self.endpoints[-1][0] != "tcp":
                raise SystemExit("--tcp wants HOST:PORT")
        self.primary = self.endpoints[0]
        self.token = args.token
        self.timeout = args.timeout
        self.tick_timeout = args.tick_timeout
        self.limits = None
        self.hello_reply = None  # the body of the last session's HELLO reply
        self.open = []

    def connect(self, ep=None, **kw):
        kw.setdefault("timeout", self.timeout)
        c = Conn(ep or self.primary, **kw)
        self.open.append(c)
        return c

    def close_all(self):
        for c in self.open:
            c.close()
        self.open = []

    def hello_body(self, **extra):
        b = {"version": 1, "client": "lpvd_conformance"}
        if self.token is not None:
            b["token"] = self.token
        b.update(extra)
        return b

    def session(self, ep=None):
        """A connection after a successful HELLO."""
        c = self.connect(ep)
        rid = c.send(HELLO, self.hello_body())
        r = c.recv_reply(rid)
        expect_reply(r, HELLO, rid, "HELLO")
        if self.limits is None and isinstance(r.body.get("limits"), dict):
            self.limits = r.body["limits"]
        self.hello_reply = r.body
        return c

    def ping(self, c, what="connection stays open"):
        """Shows that the connection is still open and in sync: a STATS request gets a frame with its
        request_id (any reply or ERROR counts)."""
        try:
            rid = c.send(STATS, {})
            f = c.recv_reply(rid)
        except Closed as e:
            raise Fail("%s: the server closed the connection (%s)" % (what, e))
        except socket.timeout:
            raise Fail("%s: no answer to a STATS request" % what)
        check(f.rid == rid, "%s: the next frame has request_id %d, expected %d (%r)" % (what, f.rid, rid, f))

    def scene_session(self, config=None, tick=True, light=None):
        """HELLO, SCENE_LOAD of the built-in test box (as an attachment), a small CONFIG, an optional
        LIGHT_SET and an optional TICK. Returns (conn, config_reply, tick_reply)."""
        c = self.session()
        expect_reply(c.request(SCENE_LOAD, {}, box_scene_glb(), timeout=self.tick_timeout), SCENE_LOAD,
                     what="set-up SCENE_LOAD (glb attachment)")
        cfg = expect_reply(c.request(CONFIG, dict(SMALL_CONFIG if config is None else config)), CONFIG,
                           what="set-up CONFIG")
        if light is not None:
            expect_reply(c.request(LIGHT_SET, light), LIGHT_SET, what="set-up LIGHT_SET")
        t = None
        if tick:
            t = expect_reply(c.request(TICK, {}, timeout=self.tick_timeout), TICK, what="set-up TICK")
        return c, cfg, t

    def max_body(self):
        lim = self.limits or {}
        for k in ("max_body", "body", "max_json", "max_body_bytes"):
            if isinstance(lim.get(k), int):
                return lim[k]
        return DEFAULT_MAX_BODY

    def max_grid(self):
        lim = self.limits or {}
        for k in ("max_grid", "grid"):
            v = lim.get(k)
            if isinstance(v, int):
                return v
            if isinstance(v, list) and v and all(isinstance(x, int) for x in v):
                return max(v)
        return None


def unique_light(tag):
    """A point light with a unique id and intensity, so that no other session has the same inputs (R7.2)."""
    return {"id": "conf-%s-%d" % (tag, os.getpid()), "type": "point", "color": [1, 1, 1],
            "intensity": 5.0 + random.random(), "position": [0.1, 1.5, 0.2]}
