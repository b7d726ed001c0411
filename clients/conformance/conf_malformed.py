"""conf_malformed.py - conformance cases: malformed frames and bodies (R2.2 - R2.9)."""

import json
import socket
import time

from conf_wire import (
    CAMERA_SET, CONFIG, GET_VOLUME, HEADER, HELLO, LIGHT_REMOVE, LIGHT_SET, MAGIC, QUERY_IRRADIANCE, STATS, SUBSCRIBE,
    VERSION, Closed, encode_frame, type_name)
from conf_core import Fail, Skip, case, check, expect_error, expect_reply


# ---------------------------------------------------------------------------
# Cases: malformed frames


@case("R2.2 R3.4", "bad magic gets ERROR BAD_MAGIC (request_id 0), then close")
def c_bad_magic(ctx):
    c = ctx.connect()
    c.send_raw(encode_frame(HELLO, 42, ctx.hello_body(), magic=b"LPVX"))
    try:
        f = c.recv_reply(timeout=5)
    except Closed:
        raise Fail("closed without ERROR BAD_MAGIC")
    except socket.timeout:
        raise Fail("no reply within 5 s")
    expect_error(f, "BAD_MAGIC", 0)
    check(c.expect_closed(), "connection not closed after BAD_MAGIC")
    return "BAD_MAGIC rid 0, closed"


@case("R2.2", "garbage (HTTP request) instead of a frame gets BAD_MAGIC, then close")
def c_bad_magic_http(ctx):
    c = ctx.connect()
    c.send_raw(b"GET / HTTP/1.1\r\nHost: x\r\n\r\n")
    try:
        f = c.recv_reply(timeout=5)
    except (Closed, socket.timeout) as e:
        raise Fail("no ERROR BAD_MAGIC (%s)" % e)
    expect_error(f, "BAD_MAGIC", 0)
    check(c.expect_closed(), "connection not closed after BAD_MAGIC")
    return "BAD_MAGIC, closed"


@case("R2.3 R3.4", "frame version 2 gets ERROR BAD_VERSION (request_id echoed, versions listed), then close")
def c_bad_frame_version(ctx):
    c = ctx.session()
    c.send_raw(encode_frame(STATS, 77, {}, version=2))
    try:
        f = c.recv_reply(timeout=5)
    except (Closed, socket.timeout) as e:
        raise Fail("no ERROR BAD_VERSION (%s)" % e)
    expect_error(f, "BAD_VERSION", 77)
    v = f.body.get("versions")
    check(isinstance(v, list) and 1 in v, "BAD_VERSION body lists no \"versions\" with 1: %r" % f.body)
    check(c.expect_closed(), "connection not closed after a bad frame version")
    return "BAD_VERSION rid 77, closed"


@case("R2.4", "non-zero flags get ERROR BAD_FRAME, then close")
def c_flags(ctx):
    c = ctx.session()
    c.send_raw(encode_frame(STATS, 9, {}, flags=1))
    try:
        f = c.recv_reply(timeout=5)
    except (Closed, socket.timeout) as e:
        raise Fail("no ERROR BAD_FRAME (%s)" % e)
    expect_error(f, "BAD_FRAME")
    check(c.expect_closed(), "connection not closed after BAD_FRAME")
    return "BAD_FRAME, closed"


@case("R2.1 R2.4", "json_length 0 and 1 get ERROR BAD_FRAME, then close")
def c_short_json(ctx):
    for jl, body in ((0, b""), (1, b"{")):
        c = ctx.session()
        c.send_raw(encode_frame(STATS, 10 + jl, raw_body=body))
        try:
            f = c.recv_reply(timeout=5)
        except (Closed, socket.timeout) as e:
            raise Fail("json_length %d: no ERROR BAD_FRAME (%s)" % (jl, e))
        expect_error(f, "BAD_FRAME")
        check(c.expect_closed(), "json_length %d: connection not closed after BAD_FRAME" % jl)
    return "both refused, closed"


def _too_large(ctx, jl, al, what):
    c = ctx.session()
    hdr = HEADER.pack(MAGIC, VERSION, CONFIG, 55, 0, jl, al)
    c.send_raw(hdr)  # only the header: the reply must come before the body (R2.5)
    try:
        f = c.recv_reply(timeout=5)
    except socket.timeout:
        raise Fail("%s: no reply within 5 s of the header alone (is the server waiting for the body?)" % what)
    except Closed:
        raise Fail("%s: closed without ERROR TOO_LARGE" % what)
    expect_error(f, "TOO_LARGE")
    check(c.expect_closed(), "%s: connection not closed after TOO_LARGE" % what)


@case("R2.5", "json_length just over the body limit gets TOO_LARGE before the body is sent, then close")
def c_too_large_body(ctx):
    lim = ctx.max_body()
    _too_large(ctx, lim + 1, 0, "json_length %d" % (lim + 1))
    _too_large(ctx, 0x7FFFFFFF, 0, "json_length 2^31-1")
    return "body limit %d" % lim


@case("R2.5", "json_length + attachment_length over the message limit gets TOO_LARGE, then close")
def c_too_large_message(ctx):
    _too_large(ctx, 2, 0xFFFFFFF0, "attachment_length 0xFFFFFFF0")
    return "TOO_LARGE, closed"


@case("R2.5a", "before HELLO a frame with any attachment, or JSON over limits.max_preauth_body, gets TOO_LARGE "
      "from the header alone, then close")
def c_preauth_too_large(ctx):
    lim = (ctx.limits or {}).get("max_preauth_body")
    if not isinstance(lim, int):
        raise Skip("HELLO limits advertise no max_preauth_body (R2.5a is a MAY)")
    for jl, al, what in ((2, 1, "a 1-byte attachment"), (2, 0xFFFFFFF0, "attachment_length 0xFFFFFFF0"),
                         (lim + 1, 0, "json_length %d" % (lim + 1))):
        c = ctx.connect()
        c.send_raw(HEADER.pack(MAGIC, VERSION, HELLO, 56, 0, jl, al))  # the header alone
        try:
            f = c.recv_reply(timeout=5)
        except socket.timeout:
            raise Fail("%s before HELLO: no reply within 5 s of the header alone" % what)
        except Closed:
            raise Fail("%s before HELLO: closed without ERROR TOO_LARGE" % what)
        expect_error(f, "TOO_LARGE", 56)
        check(str(lim) in f.body.get("message", ""), "%s: the message names no limit %d: %r"
              % (what, lim, f.body.get("message")))
        check(c.expect_closed(), "%s: connection not closed after TOO_LARGE" % what)
    return "refused at the header (max_preauth_body %d)" % lim


@case("R2.6", "connections closing mid-frame are dropped; the server keeps serving")
def c_truncated(ctx):
    cuts = [
        ("partial header", encode_frame(HELLO, 1, ctx.hello_body())[:10]),
        ("header only", encode_frame(LIGHT_SET, 2, {"id": "t", "type": "point", "intensity": 1.0})[:24]),
        ("half a body", encode_frame(LIGHT_SET, 3, {"id": "t", "type": "point", "intensity": 1.0})[:40]),
        ("body, attachment cut", encode_frame(QUERY_IRRADIANCE, 4, {"count": 100}, b"\0" * 2400)[:600]),
    ]
    for what, data in cuts:
        c = ctx.session()
        c.send_raw(data)
        time.sleep(0.05)
        # nothing may be answered for a partial frame
        try:
            f = c.recv(timeout=0.3)
            raise Fail("%s: got a reply to a partial frame: %r" % (what, f))
        except (socket.timeout, Closed):
            pass
        c.close()
    c = ctx.session()
    ctx.ping(c, "a new connection after 4 truncated ones")
    return "%d cuts, new connection served" % len(cuts)


@case("R2.7 R3.4", "invalid JSON, non-object bodies and invalid UTF-8 get BAD_JSON; connection stays open")
def c_bad_json(ctx):
    c = ctx.session()
    bodies = [b"{\"a\":", b"{'a': 1}", b"[1,2,3]", b"42", b"\"just a string\"", b"null",
              b"{\"a\":\"\xff\xfe\"}", b"{\"a\":1}xx", b"{\"a\":\"\xed\xa0\x80\"}"]
    for raw in bodies:
        rid = c.rid()
        c.send_raw(encode_frame(CONFIG, rid, raw_body=raw))
        try:
            f = c.recv_reply(rid)
        except Closed:
            raise Fail("body %r: connection closed (R2.7: it stays open)" % raw)
        expect_error(f, "BAD_JSON", rid)
    ctx.ping(c, "after %d BAD_JSON" % len(bodies))
    return "%d bodies refused, still open" % len(bodies)


@case("R2.8 R3.1", "unknown types get UNKNOWN_TYPE with the request_id; connection stays open")
def c_unknown_type(ctx):
    c = ctx.session()
    for t in (0x0042, 0x7FFF, 0x0011):
        rid = c.rid()
        c.send_raw(encode_frame(t, rid, {}))
        try:
            f = c.recv_reply(rid)
        except Closed:
            raise Fail("type 0x%04X: connection closed (R2.8: it stays open)" % t)
        expect_error(f, "UNKNOWN_TYPE", rid)
    ctx.ping(c)
    return "0x0042, 0x7FFF, 0x0011 refused, still open"


@case("R2.9", "wrong field types and missing fields get BAD_FIELD naming the field; connection stays open")
def c_bad_field(ctx):
    c, _, _ = ctx.scene_session()
    tests = [
        (CONFIG, {"iterations": "8"}, "iterations"),
        (CONFIG, {"occlusion": "yes"}, "occlusion"),
        (CONFIG, {"grid": [16, 16]}, "grid"),
        (LIGHT_SET, {"id": "l1", "type": "point", "position": [0, 1, 0]}, "intensity"),
        (LIGHT_SET, {"id": "l1", "type": "point", "intensity": "bright", "position": [0, 1, 0]}, "intensity"),
        (LIGHT_SET, {"id": "l1", "type": "laser", "intensity": 1.0, "position": [0, 1, 0]}, "type"),
        (LIGHT_SET, {"type": "point", "intensity": 1.0, "position": [0, 1, 0]}, "id"),
        (LIGHT_SET, {"id": "l1", "type": "point", "intensity": 1.0, "position": [0, 1]}, "position"),
        # values that would round to 0 in a 32-bit float, where 0 means "none" or "the default"
        (LIGHT_SET, {"id": "l1", "type": "point", "intensity": 1.0, "position": [0, 1, 0], "range": 1e-300}, "range"),
        (CONFIG, {"indirect_gain": 1e-300}, "indirect_gain"),
        (LIGHT_REMOVE, {"id": 5}, "id"),
        (QUERY_IRRADIANCE, {}, "count"),
        (QUERY_IRRADIANCE, {"count": "3"}, "count"),
        (SUBSCRIBE, {"stream": "audio"}, "stream"),
        (SUBSCRIBE, {}, "stream"),
        (GET_VOLUME, {"format": "fp8"}, "format"),
        (GET_VOLUME, {"compression": "lz4"}, "compression"),
        (CAMERA_SET, {"eye": [0, 1], "target": [0, 0, 0]}, "eye"),
    ]
    for t, body, field in tests:
        rid = c.send(t, body)
        try:
            f = c.recv_reply(rid)
        except Closed:
            raise Fail("%s %s: connection closed (R2.9: it stays open)" % (type_name(t), json.dumps(body)))
        try:
            expect_error(f, "BAD_FIELD", rid, field)
        except Fail as e:
            raise Fail("%s %s: %s" % (type_name(t), json.dumps(body), e))
    ctx.ping(c)
    return "%d requests refused naming their field" % len(tests)


@case("R2.9", "unknown fields are ignored")
def c_unknown_fields(ctx):
    c = ctx.session()
    r = c.request(CONFIG, {"iterations": 4, "x_future": True, "nested_unknown": {"a": 1}})
    expect_reply(r, CONFIG)
    r = c.request(LIGHT_SET, {"id": "u", "type": "point", "intensity": 1.0, "position": [0, 1, 0],
                              "x_vendor": "abc"})
    expect_reply(r, LIGHT_SET)
    return "CONFIG and LIGHT_SET accepted"
