"""conf_streams.py - conformance cases: VOLUME streams, ACK and deltas (R5.1, R5.2, R5.3), shq's
delta stream (R5.16), and hostile QUERY_IRRADIANCE points (R4.7)."""

import math
import struct
import time

from conf_wire import (
    ACK, CONFIG, ERROR, GET_VOLUME, LIGHT_SET, QUERY_IRRADIANCE, STATS, SUBSCRIBE, TICK, UNSUBSCRIBE, VOLUME)
from conf_payloads import SMALL_CONFIG, f32_list, xor_bytes, zstd_decompress_cli, zstd_frame_content_size
from conf_core import case, check, expect_error, expect_reply, unique_light
from conf_volume_checks import _shq_bound_checks, _shq_decode, _vol_header_checks


# ---------------------------------------------------------------------------
# Cases: streams


@case("R5.1 R3.3", "SUBSCRIBE volume + TICK sends a VOLUME stream message (request_id 0)")
def c_subscribe(ctx):
    c, cfg, _ = ctx.scene_session(tick=False, light=unique_light("sub"))
    f = expect_reply(c.request(SUBSCRIBE, {"stream": "volume", "format": "fp32", "compression": "none"}), SUBSCRIBE)
    rid = c.send(TICK, {})
    t = c.recv_reply(rid, timeout=ctx.tick_timeout)
    expect_reply(t, TICK, rid)
    v = c.recv_stream(VOLUME, timeout=ctx.tick_timeout)
    check(v.rid == 0, "VOLUME request_id %d, expected 0" % v.rid)
    _vol_header_checks(v.body, "fp32", "none", SMALL_CONFIG["grid"])
    check(v.body["keyframe"] is True, "first VOLUME is not a keyframe")
    check(v.body["tick"] == t.body.get("tick"), "VOLUME tick %r, TICK reply tick %r" % (v.body["tick"],
                                                                                     t.body.get("tick")))
    check(isinstance(v.body.get("revision"), int), "VOLUME without revision (R3.3)")
    check(len(v.att) == v.body["raw_length"], "attachment %d != raw_length %d" % (len(v.att), v.body["raw_length"]))
    g = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    check(g.body["tick"] == v.body["tick"] and g.att == v.att, "streamed volume differs from GET_VOLUME of the same tick")
    # an ACK without delta subscription: the next one is still a keyframe
    c.send(ACK, {"stream": "volume", "tick": v.body["tick"]})
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    v2 = c.recv_stream(VOLUME, timeout=ctx.tick_timeout)
    check(v2.body.get("keyframe") is True, "a subscriber without \"delta\": true got a delta (R5.3)")
    # UNSUBSCRIBE stops the stream
    expect_reply(c.request(UNSUBSCRIBE, {"stream": "volume"}), UNSUBSCRIBE)
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    ctx.ping(c)
    leftovers = [s for s in c.streams if s.type == VOLUME]
    check(not leftovers, "VOLUME received after UNSUBSCRIBE")
    return "VOLUME tick %d, %d bytes, equal to GET_VOLUME" % (v.body["tick"], len(v.att))


@case("R5.3 R5.1", "delta after ACK decodes by XOR to the same volume as a fresh GET_VOLUME")
def c_delta(ctx):
    c, cfg, _ = ctx.scene_session(tick=False, light=unique_light("delta"))
    expect_reply(c.request(SUBSCRIBE, {"stream": "volume", "format": "fp32", "compression": "none", "delta": True}),
                 SUBSCRIBE)
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    v1 = c.recv_stream(VOLUME, timeout=ctx.tick_timeout)
    check(v1.body.get("keyframe") is True, "first VOLUME is not a keyframe: %r" % v1)
    # no ACK yet: the next one must still be a keyframe
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    v2 = c.recv_stream(VOLUME, timeout=ctx.tick_timeout)
    check(v2.body.get("keyframe") is True, "a delta was sent before any ACK (R5.3): %r" % v2)
    # ACK (no reply), move the light a little, tick
    c.send(ACK, {"stream": "volume", "tick": v2.body["tick"]})
    lt = unique_light("delta")
    lt["position"] = [0.15, 1.5, 0.2]
    r = expect_reply(c.request(LIGHT_SET, lt), LIGHT_SET, what="LIGHT_SET after ACK (ACK must have no reply)")
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    v3 = c.recv_stream(VOLUME, timeout=ctx.tick_timeout)
    check(v3.body.get("keyframe") is False, "after ACK of tick %d the next VOLUME is not a delta: %r"
          % (v2.body["tick"], v3))
    check(v3.body.get("base_tick") == v2.body["tick"], "delta base_tick %r, expected the acknowledged %r"
          % (v3.body.get("base_tick"), v2.body["tick"]))
    check(v3.body.get("revision", -1) >= r.body.get("revision", 0), "delta revision %r < LIGHT_SET revision %r"
          % (v3.body.get("revision"), r.body.get("revision")))
    check(len(v3.att) == len(v2.att) == v3.body.get("raw_length"), "delta %d bytes, keyframe %d, raw_length %r"
          % (len(v3.att), len(v2.att), v3.body.get("raw_length")))
    rebuilt = xor_bytes(v2.att, v3.att)
    g = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    check(g.body.get("tick") == v3.body.get("tick"), "GET_VOLUME tick %r != delta tick %r"
          % (g.body.get("tick"), v3.body.get("tick")))
    check(rebuilt == g.att, "keyframe XOR delta differs from GET_VOLUME (%d of %d bytes differ)"
          % (sum(1 for x, y in zip(rebuilt, g.att) if x != y), len(g.att)))
    check(rebuilt != v2.att, "the moved light did not change the volume")
    zero = sum(1 for x in v3.att if x == 0)
    return "delta base %d -> tick %d, %.0f%% zero bytes, rebuilt == GET_VOLUME" % (
        v2.body["tick"], v3.body["tick"], 100.0 * zero / max(1, len(v3.att)))


@case("R5.3", "keyframes after an ACK of a tick never sent and after a grid change")
def c_delta_keyframes(ctx):
    c, cfg, _ = ctx.scene_session(tick=False, light=unique_light("dk"))
    expect_reply(c.request(SUBSCRIBE, {"stream": "volume", "format": "fp32", "compression": "none", "delta": True}),
                 SUBSCRIBE)
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    v1 = c.recv_stream(VOLUME, timeout=ctx.tick_timeout)
    c.send(ACK, {"stream": "volume", "tick": v1.body.get("tick", 0) + 1000})  # a tick that was never sent
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    v2 = c.recv_stream(VOLUME, timeout=ctx.tick_timeout)
    check(v2.body.get("keyframe") is True, "after an ACK of a tick never sent, got a delta: %r" % v2)
    c.send(ACK, {"stream": "volume", "tick": v2.body["tick"]})
    expect_reply(c.request(CONFIG, {"grid": [12, 12, 12]}), CONFIG)
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    v3 = c.recv_stream(VOLUME, timeout=ctx.tick_timeout)
    check(v3.body.get("keyframe") is True, "after a grid change, got a delta against the old grid: %r" % v3)
    _vol_header_checks(v3.body, "fp32", "none", [12, 12, 12])
    check(len(v3.att) == 12 ** 3 * 48, "attachment %d bytes, expected %d" % (len(v3.att), 12 ** 3 * 48))
    return "keyframes in both cases"


@case("R4.7", "QUERY_IRRADIANCE with NaN/Inf/zero normals and far-away points: a reply of count x 12 bytes, "
      "the server keeps serving")
def c_query_hostile(ctx):
    c, _, _ = ctx.scene_session()
    nan, inf = float("nan"), float("inf")
    pts = [(nan, 1, 0, 0, 1, 0), (0, 1, 0, nan, nan, nan), (0, 1, 0, 0, 0, 0), (inf, -inf, 0, 0, 1, 0),
           (1e30, 1e30, 1e30, 0, 1, 0), (0, 1, 0, 1e-30, 0, 0), (-5, -5, -5, 1, 1, 1), (0, 0.05, 0, 0, 1, 0)]
    att = b"".join(struct.pack("<6f", *p) for p in pts)
    f = c.recv_reply(c.send(QUERY_IRRADIANCE, {"count": len(pts)}, att), timeout=ctx.tick_timeout)
    if f.type == ERROR:
        expect_error(f, "BAD_FIELD")
        ctx.ping(c)
        return "refused with BAD_FIELD: %s" % f.body["message"]
    expect_reply(f, QUERY_IRRADIANCE)
    check(len(f.att) == len(pts) * 12, "attachment %d bytes, expected %d" % (len(f.att), len(pts) * 12))
    vals = f32_list(f.att)
    nonfinite = sum(1 for x in vals if not math.isfinite(x))
    ctx.ping(c)
    check(nonfinite == 0, "%d non-finite irradiance values returned for hostile points" % nonfinite)
    return "answered, all finite"


@case("R5.3 R5.2", "zstd fp16 delta stream: keyframe then delta, both valid zstd frames")
def c_delta_zstd(ctx):
    c, cfg, _ = ctx.scene_session(tick=False, light=unique_light("dz"))
    expect_reply(c.request(SUBSCRIBE, {"stream": "volume", "format": "fp16", "compression": "zstd", "delta": True}),
                 SUBSCRIBE)
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    v1 = c.recv_stream(VOLUME, timeout=ctx.tick_timeout)
    _vol_header_checks(v1.body, "fp16", "zstd", SMALL_CONFIG["grid"])
    c.send(ACK, {"stream": "volume", "tick": v1.body["tick"]})
    lt = unique_light("dz")
    lt["position"] = [0.12, 1.5, 0.2]
    expect_reply(c.request(LIGHT_SET, lt), LIGHT_SET)
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    v2 = c.recv_stream(VOLUME, timeout=ctx.tick_timeout)
    check(v2.body.get("keyframe") is False and v2.body.get("base_tick") == v1.body["tick"],
          "expected a delta on tick %r: %r" % (v1.body["tick"], v2))
    for v in (v1, v2):
        ok, size, why = zstd_frame_content_size(v.att)
        check(ok, why)
        if size is not None:
            check(size == v.body["raw_length"], "zstd content size %d != raw_length %d" % (size, v.body["raw_length"]))
    d1, d2 = zstd_decompress_cli(v1.att), zstd_decompress_cli(v2.att)
    if d1 is not None:
        g = expect_reply(c.request(GET_VOLUME, {"format": "fp16", "compression": "none"}), GET_VOLUME)
        check(xor_bytes(d1, d2) == g.att, "decoded keyframe XOR decoded delta differs from GET_VOLUME fp16")
        return "keyframe %d B, delta %d B, decoded and rebuilt" % (len(v1.att), len(v2.att))
    return "keyframe %d B, delta %d B (magic/size only)" % (len(v1.att), len(v2.att))


def _shq_answer(ctx, c, wait):
    """TICK on an shq delta subscription, then its answer: (the TICK reply, the
    VOLUME or None, how "none" was seen). R5.16: a tick that moved no cell
    beyond the bound sends no VOLUME and counts in STATS
    "session_stream_unchanged" (a VOLUME sent before a STATS reply arrives
    before it); a server that skips such a tick altogether (R7.3a) counts
    nothing, so "none" is also no VOLUME within ``wait`` seconds."""
    before = expect_reply(c.request(STATS, {}), STATS).body.get("session_stream_unchanged")
    check(isinstance(before, int), "STATS has no integer \"session_stream_unchanged\" (R5.16): %r" % (before,))
    t = expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    deadline = time.monotonic() + wait
    while True:
        vols = [s for s in c.streams if s.type == VOLUME]
        if vols:
            c.streams.remove(vols[0])
            return t, vols[0], None
        st = expect_reply(c.request(STATS, {}), STATS).body
        if st.get("session_stream_unchanged", 0) > before:
            check(st.get("stream_unchanged", 0) >= st["session_stream_unchanged"], "STATS stream_unchanged %r < "
                  "session_stream_unchanged %r" % (st.get("stream_unchanged"), st["session_stream_unchanged"]))
            return t, None, "counted in session_stream_unchanged"
        if time.monotonic() > deadline:
            return t, None, "no VOLUME within %g s" % wait
        time.sleep(0.02)


@case("R5.16 R5.3", "shq delta stream (bound 0.01): a keyframe, then per 1 cm light move a delta of the cells "
      "moved beyond the bound (or nothing), each rebuilt volume within the bound of GET_VOLUME fp32 of the newest "
      "tick; a TICK without a change sends no VOLUME")
def c_delta_shq(ctx):
    lt = unique_light("shq")
    c, cfg, _ = ctx.scene_session(tick=False, light=lt)
    expect_reply(c.request(SUBSCRIBE, {"stream": "volume", "compression": "shq", "delta": True,
                                       "error_bound": 0.01}), SUBSCRIBE)
    held, acked, kinds, worst = None, None, [], 0.0
    for step in range(7):
        moved = 1 <= step <= 4
        if moved:
            lt["position"] = [lt["position"][0] + 0.01] + lt["position"][1:]
            expect_reply(c.request(LIGHT_SET, lt), LIGHT_SET)
        t, v, none = _shq_answer(ctx, c, ctx.tick_timeout if step < 5 else 2.0)
        if v is None:
            check(held is not None, "no VOLUME for the first TICK of the subscription (%s)" % none)
            kinds.append("none")
        else:
            check(step < 5, "a VOLUME (tick %r, %s) for a TICK that changed nothing (R5.16)" % (
                v.body.get("tick"), "keyframe" if v.body.get("keyframe") else "delta"))
            _vol_header_checks(v.body, "fp32", "shq", SMALL_CONFIG["grid"])
            check(v.body.get("error_bound") == 0.01, "VOLUME error_bound %r, subscribed 0.01"
                  % (v.body.get("error_bound"),))
            check(v.body["tick"] == t.body.get("tick"), "VOLUME tick %r, TICK reply tick %r" % (
                v.body["tick"], t.body.get("tick")))
            if held is None:
                check(v.body["keyframe"] is True, "the first VOLUME is not a keyframe")
            elif not v.body["keyframe"]:
                check(v.body.get("base_tick") == acked, "delta against tick %r, the client acknowledged %r"
                      % (v.body.get("base_tick"), acked))
            payload = zstd_decompress_cli(v.att)
            if payload is None:
                return "no zstd tool: the stream's payloads cannot be checked (%d B keyframe)" % len(v.att)
            held, sent = _shq_decode(v.body, payload, held)
            kinds.append("keyframe" if v.body["keyframe"] else "delta/%d of %d cells%s" % (
                sent, len(held) // 48, " after blocks" if struct.unpack_from("<I", payload, 4)[0] & 4 else ""))
            acked = v.body["tick"]
            c.send(ACK, {"stream": "volume", "tick": acked})
        g = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
        check(g.body["tick"] == t.body.get("tick"), "GET_VOLUME tick %r, the newest TICK %r" % (
            g.body["tick"], t.body.get("tick")))
        worst = max(worst, _shq_bound_checks(held, g.att, 0.01, len(held) // 48, "the stream after tick %r"
                                             % g.body["tick"]))
        if not moved and step:
            kinds[-1] += " (%s)" % none
    check(any(k.startswith("delta") for k in kinds[1:5]), "no delta for a light moved 1 cm: %s" % ", ".join(kinds))
    ctx.ping(c)
    check(not [s for s in c.streams if s.type == VOLUME], "a VOLUME after the unchanged TICKs")
    return "%s; every cell within %.2f of the bound" % (", ".join(kinds), worst)
