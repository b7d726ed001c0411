"""conf_handshake.py - conformance cases: transport and handshake (R1.1, R2.1, R4.1)."""

import os
import time

from conf_wire import CONFIG, GET_VOLUME, HELLO, STATS, TICK, Closed, encode_frame
from conf_core import Fail, Skip, case, check, expect_error, expect_reply


# ---------------------------------------------------------------------------
# Cases: transport and handshake


@case("R1.1", "Unix socket is created with mode 0600")
def c_unix_mode(ctx):
    eps = [ep for ep in ctx.endpoints if ep[0] == "unix"]
    if not eps:
        raise Skip("no --unix endpoint")
    mode = os.stat(eps[0][1]).st_mode & 0o777
    check(mode == 0o600, "socket %s has mode %03o, expected 600" % (eps[0][1], mode))
    return "mode 600"


@case("R4.1 R3.1", "HELLO handshake")
def c_hello(ctx):
    c = ctx.connect()
    rid = 0x12345678
    c.send(HELLO, ctx.hello_body(), rid=rid)
    r = c.recv_reply(rid)
    expect_reply(r, HELLO, rid)
    b = r.body
    check(b.get("version") == 1, "HELLO reply version %r, expected 1" % b.get("version"))
    check(isinstance(b.get("server"), str), "HELLO reply has no string \"server\"")
    check(isinstance(b.get("session"), int), "HELLO reply has no integer \"session\"")
    check(isinstance(b.get("limits"), dict), "HELLO reply has no object \"limits\"")
    ctx.limits = b["limits"]
    return "server %r, session %d" % (b["server"], b["session"])


@case("R4.1 R2.9", "HELLO with unknown extra fields is accepted")
def c_hello_unknown_fields(ctx):
    c = ctx.connect()
    rid = c.send(HELLO, ctx.hello_body(x_future_field={"a": [1, 2]}, zz=None))
    expect_reply(c.recv_reply(rid), HELLO, rid)
    return "unknown fields ignored"


@case("R4.1", "request before HELLO gets HELLO_REQUIRED, connection stays open")
def c_hello_required(ctx):
    c = ctx.connect()
    for t, body in ((TICK, {}), (CONFIG, {"iterations": 4}), (GET_VOLUME, {})):
        rid = c.send(t, body)
        expect_error(c.recv_reply(rid), "HELLO_REQUIRED", rid)
    rid = c.send(HELLO, ctx.hello_body())
    expect_reply(c.recv_reply(rid), HELLO, rid, "HELLO after HELLO_REQUIRED")
    return "TICK/CONFIG/GET_VOLUME refused, then HELLO ok"


@case("R4.1", "HELLO with an unspoken body version gets BAD_VERSION listing versions, stays open")
def c_hello_bad_version(ctx):
    c = ctx.connect()
    rid = c.send(HELLO, ctx.hello_body(version=99))
    f = c.recv_reply(rid)
    expect_error(f, "BAD_VERSION", rid)
    v = f.body.get("versions")
    check(isinstance(v, list) and 1 in v, "BAD_VERSION body lists no \"versions\" containing 1: %r" % f.body)
    rid = c.send(HELLO, ctx.hello_body())
    try:
        expect_reply(c.recv_reply(rid), HELLO, rid, "retry HELLO version 1")
    except Closed:
        raise Fail("connection closed after a HELLO body-version error (R4.1: it stays open)")
    return "versions %r, retry ok" % v


@case("R2.1", "a frame delivered one byte at a time is parsed")
def c_byte_at_a_time(ctx):
    c = ctx.connect()
    data = encode_frame(HELLO, 7, ctx.hello_body())
    for i in range(len(data)):
        c.send_raw(data[i:i + 1])
        time.sleep(0.002)
    expect_reply(c.recv_reply(7), HELLO, 7)
    return "%d single-byte writes" % len(data)


@case("R2.1 R3.2", "several frames in one write are all parsed")
def c_coalesced(ctx):
    c = ctx.connect()
    data = encode_frame(HELLO, 1, ctx.hello_body()) + encode_frame(STATS, 2, {}) + encode_frame(CONFIG, 3, {})
    c.send_raw(data)
    got = [c.recv_reply() for _ in range(3)]
    check([f.rid for f in got] == [1, 2, 3], "request_ids %r, expected [1, 2, 3]" % [f.rid for f in got])
    expect_reply(got[0], HELLO, 1)
    return "3 replies in order"
