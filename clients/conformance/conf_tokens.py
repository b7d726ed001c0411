"""conf_tokens.py - conformance cases: token authentication on every transport (R1.2, R4.2);
skipped without --token."""

import socket

from conf_wire import GET_VOLUME, HELLO, Closed, endpoint_str
from conf_core import Fail, Skip, case, check, expect_error, expect_reply


# ---------------------------------------------------------------------------
# Cases: tokens


def _token_cases_endpoints(ctx):
    if ctx.token is None:
        raise Skip("no --token given (server without a token)")
    return ctx.endpoints


@case("R1.2 R4.2", "HELLO without the token gets UNAUTHORIZED, then close (every transport)")
def c_token_missing(ctx):
    out = []
    for ep in _token_cases_endpoints(ctx):
        c = ctx.connect(ep)
        rid = c.send(HELLO, {"version": 1, "client": "lpvd_conformance"})
        try:
            f = c.recv_reply(rid, timeout=5)
        except (Closed, socket.timeout) as e:
            raise Fail("%s: no ERROR UNAUTHORIZED (%s)" % (endpoint_str(ep), e))
        expect_error(f, "UNAUTHORIZED", rid)
        check(c.expect_closed(), "%s: connection not closed after UNAUTHORIZED" % endpoint_str(ep))
        out.append(ep[0])
    return "refused and closed on %s" % ", ".join(out)


@case("R4.2", "HELLO with a wrong token gets UNAUTHORIZED, then close")
def c_token_wrong(ctx):
    out = []
    for ep in _token_cases_endpoints(ctx):
        for bad in (ctx.token + "x", "", 12345):
            c = ctx.connect(ep)
            rid = c.send(HELLO, {"version": 1, "token": bad})
            try:
                f = c.recv_reply(rid, timeout=5)
            except (Closed, socket.timeout) as e:
                raise Fail("%s token %r: no ERROR UNAUTHORIZED (%s)" % (endpoint_str(ep), bad, e))
            if bad == 12345 and f.err_name == "BAD_FIELD":
                c.close()
                continue  # a non-string token may be refused as a bad field
            expect_error(f, "UNAUTHORIZED", rid)
            check(c.expect_closed(), "%s: connection not closed after UNAUTHORIZED" % endpoint_str(ep))
        out.append(ep[0])
    return "refused and closed on %s" % ", ".join(out)


@case("R4.2 R1.2", "HELLO with the right token succeeds (every transport)")
def c_token_right(ctx):
    out = []
    for ep in _token_cases_endpoints(ctx):
        c = ctx.connect(ep)
        rid = c.send(HELLO, ctx.hello_body())
        expect_reply(c.recv_reply(rid), HELLO, rid, "HELLO with token over %s" % ep[0])
        ctx.ping(c)
        out.append(ep[0])
    return "accepted on %s" % ", ".join(out)


@case("R4.1 R4.2", "requests before HELLO on a token server get HELLO_REQUIRED, not data")
def c_token_before_hello(ctx):
    _token_cases_endpoints(ctx)
    c = ctx.connect()
    rid = c.send(GET_VOLUME, {})
    f = c.recv_reply(rid)
    check(f.err_name in ("HELLO_REQUIRED", "UNAUTHORIZED"), "GET_VOLUME before HELLO: got %r" % f)
    return f.err_name
