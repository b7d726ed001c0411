"""conf_replies.py - conformance cases: replies, ordering, revisions and the ERROR body (R3)."""


from conf_wire import CONFIG, ERROR, GET_VOLUME, LIGHT_REMOVE, LIGHT_SET, REPLY, STATS, TICK, encode_frame, type_name
from conf_payloads import f32_list
from conf_core import case, check, expect_error, expect_reply, unique_light


# ---------------------------------------------------------------------------
# Cases: replies, ordering, revisions


@case("R3.1", "reply type is request|0x8000 and request_id is echoed (large ids)")
def c_reply_ids(ctx):
    c = ctx.session()
    for rid, t, body in ((0xFFFFFFFF, STATS, {}), (0x80000000, CONFIG, {}), (0xDEADBEEF, LIGHT_SET,
                         {"id": "r", "type": "point", "intensity": 1.0, "position": [0, 1, 0]}),
                         (3, LIGHT_REMOVE, {"id": "r"})):
        c.send(t, body, rid=rid)
        f = c.recv_reply(rid)
        expect_reply(f, t, rid)
    return "4 request types, ids up to 0xFFFFFFFF"


@case("R3.2 R3.1", "pipelined requests in one write are answered in order")
def c_ordering(ctx):
    c = ctx.session()
    frames = [
        (LIGHT_SET, {"id": "a", "type": "point", "intensity": 1.0, "position": [0, 1, 0]}, LIGHT_SET | REPLY),
        (LIGHT_SET, {"id": "b", "type": "point", "intensity": 2.0, "position": [0.5, 1, 0]}, LIGHT_SET | REPLY),
        (CONFIG, None, ERROR),  # raw bad JSON
        (0x0042, {}, ERROR),
        (CONFIG, {"iterations": 3}, CONFIG | REPLY),
        (LIGHT_REMOVE, {"id": "a"}, LIGHT_REMOVE | REPLY),
        (STATS, {}, STATS | REPLY),
        (LIGHT_SET, {"id": "a", "type": "point", "intensity": 3.0, "position": [0, 1.2, 0]}, LIGHT_SET | REPLY),
    ]
    data = b""
    base = 1000
    for i, (t, body, _) in enumerate(frames):
        if body is None:
            data += encode_frame(t, base + i, raw_body=b"{not json")
        else:
            data += encode_frame(t, base + i, body)
    c.send_raw(data)
    got = []
    for _ in frames:
        got.append(c.recv_reply())
    rids = [f.rid for f in got]
    check(rids == list(range(base, base + len(frames))), "replies in order %r, expected %r"
          % (rids, list(range(base, base + len(frames)))))
    for f, (t, _, want) in zip(got, frames):
        check(f.type == want, "request %s rid %d: got %r, expected type 0x%04X" % (type_name(t), f.rid, f, want))
    revs = [f.body.get("revision") for f in got if f.type in (LIGHT_SET | REPLY, LIGHT_REMOVE | REPLY)]
    check(all(isinstance(r, int) for r in revs), "state-changing replies without integer revision: %r" % revs)
    check(all(b > a for a, b in zip(revs, revs[1:])), "revisions of the light updates not increasing: %r" % revs)
    return "%d replies in order, revisions %r" % (len(frames), revs)


@case("R3.3", "every state change increases the revision; volumes reflect them")
def c_revisions(ctx):
    c, cfg, _ = ctx.scene_session(tick=False)
    seq = []
    steps = [
        (LIGHT_SET, {"id": "rv", "type": "point", "intensity": 3.0, "position": [0, 1, 0]}),
        (LIGHT_SET, {"id": "rv", "type": "point", "intensity": 4.0, "position": [0.2, 1, 0]}),
        (CONFIG, {"iterations": 5}),
        (LIGHT_REMOVE, {"id": "rv"}),
        (LIGHT_SET, {"id": "rv2", "type": "spot", "intensity": 4.0, "position": [0, 1.8, 0],
                     "direction": [0, -1, 0], "inner_cone": 0.3, "outer_cone": 0.6}),
    ]
    for t, body in steps:
        f = expect_reply(c.request(t, body), t)
        r = f.body.get("revision")
        check(isinstance(r, int), "%s reply has no integer revision: %r" % (type_name(t), f.body))
        seq.append(r)
    check(all(b > a for a, b in zip(seq, seq[1:])), "revisions not strictly increasing: %r" % seq)
    t = expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    check(isinstance(t.body.get("revision"), int) and t.body["revision"] >= seq[-1],
          "TICK reply revision %r < last update revision %d" % (t.body.get("revision"), seq[-1]))
    v = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}, timeout=ctx.tick_timeout),
                     GET_VOLUME)
    check(isinstance(v.body.get("revision"), int) and v.body["revision"] >= seq[-1],
          "GET_VOLUME revision %r < last update revision %d" % (v.body.get("revision"), seq[-1]))
    return "revisions %r, volume revision %d" % (seq, v.body["revision"])


@case("R3.3", "an update is reflected by the next tick's volume")
def c_update_reflected(ctx):
    c, _, _ = ctx.scene_session(light=unique_light("refl"))
    a = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    r = expect_reply(c.request(LIGHT_SET, {"id": "refl-extra", "type": "point", "intensity": 50.0,
                                           "position": [-0.6, 0.5, 0.3]}), LIGHT_SET)
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    b = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    check(b.body.get("revision", -1) >= r.body.get("revision", 0),
          "volume revision %r < LIGHT_SET revision %r" % (b.body.get("revision"), r.body.get("revision")))
    check(b.body.get("tick") != a.body.get("tick"), "tick number did not change (%r)" % b.body.get("tick"))
    check(a.att != b.att, "the volume did not change after adding a 50 W/sr light")
    ea = sum(f32_list(a.att)[0::4])
    eb = sum(f32_list(b.att)[0::4])
    check(eb > ea, "sum of DC coefficients did not grow after adding a light (%.4g -> %.4g)" % (ea, eb))
    return "DC sum %.4g -> %.4g" % (ea, eb)


@case("R3.4", "every ERROR body is {code, name, message} with the table's code/name pairs")
def c_error_shape(ctx):
    c = ctx.connect()
    rid = c.send(TICK, {})
    f = c.recv_reply(rid)
    expect_error(f, "HELLO_REQUIRED", rid)
    check(f.body["code"] == 9, "HELLO_REQUIRED with code %r" % f.body["code"])
    check(len(f.body["message"]) > 0, "empty message")
    c2 = ctx.session()
    rid = c2.send(0x0077, {})
    f = c2.recv_reply(rid)
    expect_error(f, "UNKNOWN_TYPE", rid)
    check(f.body["code"] == 6, "UNKNOWN_TYPE with code %r" % f.body["code"])
    return "shape and codes ok"
