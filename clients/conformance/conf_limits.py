"""conf_limits.py - conformance cases: the server ending sessions and refusing what is over its
limits: BYE (R4.8), the idle timeout (R4.9), the handshake deadline (R4.1a), triangles,
textures and clients over the limits (R4.5)."""

import socket
import time

from conf_wire import BYE, BYE_REPLY, HELLO, REPLY, SCENE_LOAD, STATS, Closed, encode_frame
from conf_payloads import textured_glb, triangles_glb
from conf_core import Fail, Skip, case, check, expect_error, expect_reply


@case("R4.8 R3.1", "BYE gets its reply, then the server closes")
def c_bye(ctx):
    c = ctx.session()
    rid = c.send(BYE, {})
    f = c.recv_reply(rid)
    expect_reply(f, BYE, rid)
    check(c.expect_closed(), "connection not closed after the BYE reply")
    return "BYE reply, closed"


@case("R4.9", "an idle session is sent BYE (0x800F, request_id 0) and closed")
def c_idle(ctx):
    if not ctx.args.idle_timeout:
        raise Skip("no --idle-timeout given")
    c = ctx.session()
    t0 = time.monotonic()
    try:
        f = c.recv_reply(timeout=ctx.args.idle_timeout + 5)
    except socket.timeout:
        raise Fail("no BYE within idle timeout %g s + 5 s" % ctx.args.idle_timeout)
    except Closed:
        raise Fail("closed without BYE after %.1f s" % (time.monotonic() - t0))
    dt = time.monotonic() - t0
    check(f.type == BYE_REPLY and f.rid == 0, "expected BYE 0x800F request_id 0, got %r" % f)
    check(dt >= ctx.args.idle_timeout * 0.8, "BYE after %.1f s, before the idle timeout %g s" % (dt, ctx.args.idle_timeout))
    check(c.expect_closed(), "connection not closed after the idle BYE")
    return "BYE after %.1f s, closed" % dt


@case("R4.9", "bytes of a frame never completed do not keep a session alive: BYE after the idle timeout")
def c_idle_partial_frame(ctx):
    if not ctx.args.idle_timeout:
        raise Skip("no --idle-timeout given")
    c = ctx.session()
    data = encode_frame(STATS, 3, {"pad": "p" * 200})
    t0 = time.monotonic()
    bound = ctx.args.idle_timeout * 3 + 5
    f = None
    for i in range(len(data) - 1):  # never the last byte
        if time.monotonic() - t0 > bound:
            break
        c.send_raw(data[i:i + 1])
        try:
            f = c.recv_reply(timeout=0.25)
            break
        except socket.timeout:
            continue
        except Closed:
            raise Fail("closed without BYE after %.1f s" % (time.monotonic() - t0))
    dt = time.monotonic() - t0
    if f is None:
        raise Fail("no BYE within %.0f s while trickling a frame (idle timeout %g s)" % (dt, ctx.args.idle_timeout))
    check(f.type == BYE_REPLY and f.rid == 0, "expected BYE 0x800F request_id 0, got %r" % f)
    check(c.expect_closed(), "connection not closed after the idle BYE")
    return "BYE after %.1f s of trickling" % dt


@case("R4.1a", "a connection that says no HELLO gets ERROR LIMIT when limits.handshake_timeout passes, then close")
def c_handshake_deadline(ctx):
    t = (ctx.limits or {}).get("handshake_timeout")
    if not isinstance(t, (int, float)) or t <= 0:
        raise Skip("HELLO limits advertise no handshake_timeout")
    if t > 15:
        raise Skip("handshake_timeout %g s is too long to wait for here" % t)
    c = ctx.connect()
    t0 = time.monotonic()
    try:
        f = c.recv_reply(timeout=t * 3 + 5)
    except socket.timeout:
        raise Fail("still open %.0f s after connecting (handshake_timeout %g s)" % (time.monotonic() - t0, t))
    except Closed:
        raise Fail("closed without ERROR LIMIT")
    dt = time.monotonic() - t0
    expect_error(f, "LIMIT", 0)
    check(dt >= t * 0.8, "LIMIT after %.1f s, before the handshake_timeout %g s" % (dt, t))
    check(c.expect_closed(), "connection not closed after the handshake LIMIT")
    return "LIMIT after %.1f s (handshake_timeout %g s), closed" % (dt, t)


@case("R4.5", "a scene over the triangle limit gets LIMIT; one at the limit loads")
def c_limit_triangles(ctx):
    c = ctx.session()
    lim = (ctx.limits or {}).get("max_triangles")
    if not isinstance(lim, int):
        raise Fail("HELLO limits advertise no integer max_triangles; cannot aim just above it")
    if lim > 200000:
        raise Skip("the server's max_triangles %d is too large to exceed cheaply (run it with a small "
                   "--max-triangles)" % lim)
    rid = c.send(SCENE_LOAD, {}, triangles_glb(lim + 1))
    expect_error(c.recv_reply(rid, timeout=ctx.tick_timeout), "LIMIT", rid)
    f = expect_reply(c.request(SCENE_LOAD, {}, triangles_glb(lim), timeout=ctx.tick_timeout), SCENE_LOAD,
                     what="a scene with exactly max_triangles")
    check(f.body.get("scene", {}).get("triangles") == lim, "triangles %r, expected %d"
          % (f.body.get("scene", {}).get("triangles"), lim))
    return "%d refused, %d loaded" % (lim + 1, lim)


@case("R4.5", "a scene with a texture over the texture limit gets LIMIT")
def c_limit_texture(ctx):
    c = ctx.session()
    lim = (ctx.limits or {}).get("max_texture")
    if not isinstance(lim, int):
        raise Fail("HELLO limits advertise no integer max_texture; cannot aim just above it")
    if lim > 32768:
        raise Skip("the server's max_texture %d is too large to exceed cheaply" % lim)
    f = expect_reply(c.request(SCENE_LOAD, {}, textured_glb(4, 4), timeout=ctx.tick_timeout), SCENE_LOAD,
                     what="a scene with a 4x4 texture")
    rid = c.send(SCENE_LOAD, {}, textured_glb(lim + 1, 1))
    expect_error(c.recv_reply(rid, timeout=ctx.tick_timeout), "LIMIT", rid)
    return "%dx1 texture refused (max_texture %d)" % (lim + 1, lim)


@case("R4.5", "a connection over max_clients gets ERROR LIMIT")
def c_limit_clients(ctx):
    lim = (ctx.limits or {}).get("max_clients")
    if not isinstance(lim, int):
        raise Fail("HELLO limits advertise no integer max_clients")
    if lim > 256:
        raise Skip("the server's max_clients %d is too large to exceed cheaply" % lim)
    # wait until the server has seen the previous cases' connections close (STATS clients == 1: this one)
    first = ctx.session()
    t_end = time.monotonic() + 5
    while time.monotonic() < t_end:
        f = first.request(STATS, {})
        n = f.body.get("clients") if f.type == STATS | REPLY else None
        if not isinstance(n, int) or n <= 1:
            break
        time.sleep(0.1)
    if not isinstance(n, int):
        time.sleep(0.5)
    held = [first] + [ctx.session() for _ in range(lim - 1)]
    extra = ctx.connect()
    rid = 0
    try:
        # A server may refuse at accept, before any request: read first, so
        # the refusal is not lost to a reset caused by writing into a
        # connection the server has already closed.
        try:
            f = extra.recv_reply(timeout=1)
        except socket.timeout:
            rid = extra.send(HELLO, ctx.hello_body())
            f = extra.recv_reply(timeout=5)
    except Closed:
        raise Fail("connection %d was closed without ERROR LIMIT" % (lim + 1))
    except socket.timeout:
        raise Fail("connection %d got no answer within 5 s" % (lim + 1))
    expect_error(f, "LIMIT")
    check(f.rid in (0, rid), "ERROR LIMIT with request_id %d (expected 0 or the HELLO's %d)" % (f.rid, rid))
    held[0].close()
    extra.close()
    again, why = None, ""
    for _ in range(15):  # a slot is free again once the server has seen the close
        time.sleep(0.2)
        try:
            again = ctx.session()
            break
        except (Fail, Closed) as e:
            why = str(e)
    check(again is not None, "no connection accepted after one of %d was closed: %s" % (lim, why))
    ctx.ping(again)
    return "connection %d refused, a freed slot is reusable" % (lim + 1)
