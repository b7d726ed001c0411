"""conf_updates.py - conformance cases: SCENE_UPDATE (materials, nodes, animation) and CAMERA_SET
(R3.3, R4.4c)."""

import json

from conf_wire import CAMERA_SET, CONFIG, GET_VOLUME, SCENE_LOAD, SCENE_UPDATE, TICK
from conf_payloads import SMALL_CONFIG, box_scene_glb
from conf_core import Fail, case, check, expect_error, expect_reply, unique_light


@case("R3.3 R2.9", "SCENE_UPDATE of a material and a node: revisions increase, the volume changes; "
      "out-of-range indices get BAD_FIELD")
def c_scene_update(ctx):
    c, _, _ = ctx.scene_session(light=unique_light("su"))
    v0 = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    r1 = expect_reply(c.request(SCENE_UPDATE, {"materials": [{"material": 0, "base_color": [0.2, 0.2, 0.9, 1]}]}),
                      SCENE_UPDATE)
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    v1 = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    r2 = expect_reply(c.request(SCENE_UPDATE, {"nodes": [{"node": 0, "rotation": [0, 0.0871557, 0, 0.9961947]}]}),
                      SCENE_UPDATE)
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    v2 = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    r3 = expect_reply(c.request(SCENE_UPDATE, {"nodes": [{"node": 1, "translation": [0.4, 1.0, 0.3]}]}),
                      SCENE_UPDATE)
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    v3 = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    d, a, b, e = v0.body.get("revision"), r1.body.get("revision"), r2.body.get("revision"), r3.body.get("revision")
    check(all(isinstance(x, int) for x in (a, b, d, e)), "revisions %r %r %r %r" % (d, a, b, e))
    check(d < a < b < e, "revisions not increasing: volume %r, material update %r, node updates %r, %r"
          % (d, a, b, e))
    check(v1.att != v0.att, "recolouring the white material did not change the volume")
    check(v2.att != v1.att, "rotating the box's mesh node (node 0) by 10 degrees did not change the volume")
    check(v3.att != v2.att, "moving node 1, the node carrying the glb's point light (KHR_lights_punctual), "
          "from (0, 1.6, 0) to (0.4, 1, 0.3) did not change the volume: the light did not follow its node")
    check(v3.body.get("revision", -1) >= e, "volume revision %r < update revision %r" % (v3.body.get("revision"), e))
    for body, field in (({"nodes": [{"node": 99, "translation": [0, 0, 0]}]}, "node"),
                        ({"materials": [{"material": 99, "base_color": [1, 1, 1, 1]}]}, "material"),
                        ({"nodes": [{"node": 0, "translation": [0, 0]}]}, "translation")):
        rid = c.send(SCENE_UPDATE, body)
        try:
            expect_error(c.recv_reply(rid), "BAD_FIELD", rid, field)
        except Fail as e:
            raise Fail("SCENE_UPDATE %s: %s" % (json.dumps(body), e))
    return "revisions %d < %d < %d < %d; material, mesh node and light node each changed the volume; " \
        "out-of-range refused" % (d, a, b, e)


@case("R4.4c", "SCENE_UPDATE animation poses the scene at a time (the volume changes); a bad time or name, "
      "or the built-in scene, gets BAD_FIELD naming animation")
def c_scene_update_animation(ctx):
    c = ctx.session()
    expect_reply(c.request(SCENE_LOAD, {}, box_scene_glb(animated=True), timeout=ctx.tick_timeout), SCENE_LOAD)
    expect_reply(c.request(CONFIG, dict(SMALL_CONFIG)), CONFIG)
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    v0 = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    r = expect_reply(c.request(SCENE_UPDATE, {"animation": {"name": "Swing", "time": 1.0}},
                               timeout=ctx.tick_timeout), SCENE_UPDATE)
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    v1 = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    check(isinstance(r.body.get("revision"), int), "reply has no integer revision: %r" % r.body)
    check(v1.att != v0.att, "posing the box at 1 s of \"Swing\" (turned 90 degrees) did not change the volume")
    for body in ({"animation": {"time": -1}}, {"animation": {"time": "soon"}}, {"animation": 5},
                 {"animation": {"name": "Nope", "time": 0.5}}, {"animation": {"time": 1, "speed": 2}}):
        rid = c.send(SCENE_UPDATE, body)
        try:
            expect_error(c.recv_reply(rid, timeout=ctx.tick_timeout), "BAD_FIELD", rid, "animation")
        except Fail as e:
            raise Fail("SCENE_UPDATE %s: %s" % (json.dumps(body), e))
    b = ctx.session()
    rid = b.send(SCENE_UPDATE, {"animation": {"time": 1}})
    expect_error(b.recv_reply(rid), "BAD_FIELD", rid, "animation")
    return "posed at 1 s: the volume changed; 5 bad requests and the built-in scene refused"


@case("R3.3", "CAMERA_SET with a scene camera (the default scene's) and with eye/target")
def c_camera_set(ctx):
    c = ctx.session()
    f = expect_reply(c.request(CAMERA_SET, {"camera": 0}), CAMERA_SET, what="CAMERA_SET {camera: 0}")
    r0 = f.body.get("revision")
    f = expect_reply(c.request(CAMERA_SET, {"eye": [0, 1, 3], "target": [0, 1, 0], "up": [0, 1, 0], "fov_deg": 50,
                                            "width": 32, "height": 32}), CAMERA_SET)
    r1 = f.body.get("revision")
    check(isinstance(r0, int) and isinstance(r1, int) and r1 > r0, "revisions %r then %r" % (r0, r1))
    return "revisions %d, %d" % (r0, r1)
