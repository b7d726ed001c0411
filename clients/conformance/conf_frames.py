"""conf_frames.py - conformance cases: FRAME streams, exr frames and the ao term (R6.1 - R6.5)."""

import json

from conf_wire import CAMERA_SET, CONFIG, FRAME, GET_FRAME, SUBSCRIBE, TICK, UNSUBSCRIBE, type_name
from conf_payloads import SMALL_CONFIG
from conf_core import Fail, case, check, expect_error, expect_reply, unique_light
from conf_volume_checks import IV_CONFIG, _iv_techniques, _plan_checks


@case("R6.3 R6.1", "SUBSCRIBE frame + TICK sends a FRAME stream message (request_id 0)")
def c_frame_stream(ctx):
    c, _, _ = ctx.scene_session(tick=False, light=unique_light("fs"))
    expect_reply(c.request(CAMERA_SET, {"eye": [0, 1, 3.5], "target": [0, 1, 0], "fov_deg": 40, "width": 40,
                                        "height": 30}), CAMERA_SET)
    expect_reply(c.request(SUBSCRIBE, {"stream": "frame", "format": "rgba8", "compression": "none"}), SUBSCRIBE)
    t = expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    f = c.recv_stream(FRAME, timeout=ctx.tick_timeout)
    check(f.rid == 0, "FRAME request_id %d" % f.rid)
    h = f.body
    check(h.get("width") == 40 and h.get("height") == 30, "FRAME %rx%r, expected 40x30" % (h.get("width"),
                                                                                        h.get("height")))
    check(h.get("format") == "rgba8" and len(f.att) == 40 * 30 * 4 == h.get("raw_length"),
          "FRAME format %r, %d bytes, raw_length %r" % (h.get("format"), len(f.att), h.get("raw_length")))
    check(h.get("tick") == t.body.get("tick"), "FRAME tick %r, TICK reply %r" % (h.get("tick"), t.body.get("tick")))
    check(isinstance(h.get("revision"), int), "FRAME without revision")
    _plan_checks(h.get("plan"), "FRAME header")
    return "FRAME tick %r, %d bytes" % (h.get("tick"), len(f.att))


@case("R6.2", "GET_FRAME exr (linear radiance file) and terms")
def c_frame_exr(ctx):
    c, _, _ = ctx.scene_session(tick=False)
    expect_reply(c.request(CAMERA_SET, {"eye": [0, 1, 3.5], "target": [0, 1, 0], "fov_deg": 40, "width": 32,
                                        "height": 24}), CAMERA_SET)
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    e = expect_reply(c.request(GET_FRAME, {"format": "exr", "terms": "indirect"}, timeout=ctx.tick_timeout),
                     GET_FRAME)
    check(e.att[:4] == b"\x76\x2f\x31\x01", "exr attachment does not start with the OpenEXR magic")
    check(e.body.get("units") == "W/(m^2 sr)", "exr units %r" % e.body.get("units"))
    check(e.body.get("terms") == "indirect", "terms %r, expected indirect" % e.body.get("terms"))
    check(e.body.get("compression") in (None, "none"), "exr compression %r (R6.2)" % e.body.get("compression"))
    return "exr %d B" % len(e.att)


@case("R6.5 R2.9", "terms ao: GET_FRAME and SUBSCRIBE get BAD_FIELD naming terms for technique lpv and for iv with "
      "iv_ao off; with iv_ao on a grey frame of fractions in [0, 1], units \"1\", also streamed")
def c_frame_ao(ctx):
    c, _, _ = ctx.scene_session(tick=False, config=dict(SMALL_CONFIG, technique="lpv"), light=unique_light("ao"))
    expect_reply(c.request(CAMERA_SET, {"eye": [0, 1, 3.5], "target": [0, 1, 0], "fov_deg": 40, "width": 40,
                                        "height": 30}), CAMERA_SET)
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)

    def refused(what):
        for ftype, body in ((GET_FRAME, {"format": "rgba8", "terms": "ao"}),
                            (SUBSCRIBE, {"stream": "frame", "format": "rgba8", "terms": "ao"})):
            rid = c.send(ftype, body)
            try:
                expect_error(c.recv_reply(rid, timeout=ctx.tick_timeout), "BAD_FIELD", rid, "terms")
            except Fail as e:
                raise Fail("%s %s (%s): %s" % (type_name(ftype), json.dumps(body), what, e))
    refused("technique lpv")
    if "iv" not in _iv_techniques(ctx):
        return "technique lpv: refused naming terms (HELLO lists no \"iv\")"
    expect_reply(c.request(CONFIG, IV_CONFIG), CONFIG)
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    refused("technique iv, iv_ao off")
    expect_reply(c.request(CONFIG, {"iv_ao": True}), CONFIG)
    t = expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    f = expect_reply(c.request(GET_FRAME, {"format": "rgba8", "compression": "none", "terms": "ao",
                                           "transparent": True}, timeout=ctx.tick_timeout), GET_FRAME)
    h = f.body
    check(h.get("terms") == "ao" and h.get("units") == "1", "ao frame: terms %r, units %r (R6.5: \"ao\", \"1\")"
          % (h.get("terms"), h.get("units")))
    check("exposure_ev" not in h and "exposure" not in h, "ao frame header carries an exposure: %r"
          % ({k: h[k] for k in ("exposure", "exposure_ev") if k in h},))
    check(h.get("tick") == t.body.get("tick") and len(f.att) == 40 * 30 * 4 == h.get("raw_length"),
          "ao frame tick %r (TICK %r), %d bytes" % (h.get("tick"), t.body.get("tick"), len(f.att)))
    seen = [f.att[i] / 255.0 for i in range(0, len(f.att), 4) if f.att[i + 3] == 255]
    check(all(f.att[i] == f.att[i + 1] == f.att[i + 2] for i in range(0, len(f.att), 4)), "the ao frame is not grey")
    check(len(seen) > 100, "only %d pixels see geometry" % len(seen))
    check(all(0.0 <= v <= 1.0 for v in seen), "ao values outside [0, 1]")
    check(max(seen) > 0.5, "no open surface (ao at most %.3f) in a box seen from its open side" % max(seen))
    e = expect_reply(c.request(GET_FRAME, {"format": "exr", "terms": "ao"}, timeout=ctx.tick_timeout), GET_FRAME)
    check(e.att[:4] == b"\x76\x2f\x31\x01" and e.body.get("units") == "1", "ao exr: magic %r, units %r"
          % (e.att[:4], e.body.get("units")))
    expect_reply(c.request(SUBSCRIBE, {"stream": "frame", "format": "rgba8", "compression": "none", "terms": "ao"}),
                 SUBSCRIBE)
    t2 = expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    s = c.recv_stream(FRAME, timeout=ctx.tick_timeout)
    check(s.body.get("terms") == "ao" and s.body.get("units") == "1" and s.body.get("tick") == t2.body.get("tick"),
          "streamed ao FRAME: terms %r, units %r, tick %r (TICK %r)" % (s.body.get("terms"), s.body.get("units"),
                                                                        s.body.get("tick"), t2.body.get("tick")))
    expect_reply(c.request(UNSUBSCRIBE, {"stream": "frame"}), UNSUBSCRIBE)
    return "refused for lpv and iv_ao off; ao on: %d pixels in [%.3f, %.3f], mean %.3f; exr and stream" % (
        len(seen), min(seen), max(seen), sum(seen) / len(seen))
