"""conf_frame_stats.py - conformance cases: what a session reads about its tick besides the
volume: GET_FRAME (R6.1, R6.2), STATS (R3.1, R7.6a) and the tick plan (R8)."""

import json
import struct

from conf_wire import CAMERA_SET, CONFIG, GET_FRAME, GET_VOLUME, STATS, TICK
from conf_core import Skip, case, check, expect_reply, unique_light
from conf_volume_checks import IV_CONFIG, PLAN_PASSES, _iv_techniques, _plan_checks, _vol_header_checks


# ---------------------------------------------------------------------------
# Cases: frames, stats, the tick plan (bye and idle: conf_limits.py)


@case("R6.1 R6.2", "GET_FRAME rgba8 (width x height x 4) and png (complete file)")
def c_frame(ctx):
    c, cfg, _ = ctx.scene_session(tick=False)
    expect_reply(c.request(CAMERA_SET, {"eye": [0, 1, 3.5], "target": [0, 1, 0], "fov_deg": 40, "width": 64,
                                        "height": 48}), CAMERA_SET)
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    f = expect_reply(c.request(GET_FRAME, {"format": "rgba8", "compression": "none"}, timeout=ctx.tick_timeout),
                     GET_FRAME)
    h = f.body
    check(h.get("width") == 64 and h.get("height") == 48, "frame %rx%r, expected 64x48" % (h.get("width"),
                                                                                        h.get("height")))
    check(h.get("raw_length") == 64 * 48 * 4 and len(f.att) == 64 * 48 * 4,
          "rgba8 raw_length %r / %d bytes, expected %d" % (h.get("raw_length"), len(f.att), 64 * 48 * 4))
    check(h.get("units") == "sRGB", "rgba8 units %r, expected sRGB" % h.get("units"))
    check(len(set(f.att)) > 4, "the rgba8 frame is flat")
    p = expect_reply(c.request(GET_FRAME, {"format": "png"}, timeout=ctx.tick_timeout), GET_FRAME)
    check(p.att[:8] == b"\x89PNG\r\n\x1a\n", "png attachment does not start with the PNG signature")
    check(p.body.get("compression") in (None, "none"), "png compression %r (R6.2: never compressed further)"
          % p.body.get("compression"))
    w, hh = struct.unpack(">II", p.att[16:24])
    check((w, hh) == (64, 48), "PNG IHDR %dx%d, expected 64x48" % (w, hh))
    return "rgba8 %d B, png %d B" % (len(f.att), len(p.att))


@case("R3.1", "STATS reply carries stages, plan, clients, sessions, worlds, queues, bytes_sent, ticks")
def c_stats(ctx):
    c = ctx.session()
    f = expect_reply(c.request(STATS, {}), STATS)
    missing = [k for k in ("stages", "plan", "clients", "sessions", "worlds", "queues", "bytes_sent", "ticks")
               if k not in f.body]
    check(not missing, "STATS reply lacks %r" % missing)
    return "clients %r, worlds %r, ticks %r" % (f.body["clients"], f.body["worlds"], f.body["ticks"])


@case("R7.6a", "STATS memory: the budget is HELLO's limits.max_memory and its parts, after a tick, fit in it")
def c_stats_memory(ctx):
    c, _, _ = ctx.scene_session()
    budget = (ctx.limits or {}).get("max_memory")
    check(isinstance(budget, int) and not isinstance(budget, bool) and budget > 0,
          "HELLO limits.max_memory is %r, expected a positive integer" % (budget,))
    m = expect_reply(c.request(STATS, {}), STATS).body.get("memory")
    check(isinstance(m, dict), "STATS has no memory object: %r" % (m,))
    parts = ("worlds", "scenes", "requests", "replies")
    bad = [k for k in parts if not isinstance(m.get(k), int) or isinstance(m.get(k), bool) or m.get(k) < 0]
    check(not bad, "STATS memory parts %r are not non-negative integers: %r" % (bad, m))
    check(m.get("budget") == budget, "STATS memory.budget %r, HELLO limits.max_memory %r" % (m.get("budget"), budget))
    total = sum(m[k] for k in parts)
    check(total <= budget, "the parts hold %d bytes, over the budget of %d" % (total, budget))
    check(m["worlds"] > 0, "a world has ticked but memory.worlds is 0")
    return "%s of %d bytes" % (", ".join("%s %d" % (k, m[k]) for k in parts), budget)


@case("R8.1 R8.2 R5.6", "the tick plan (every pass named, run + reason) is in STATS, the TICK reply, "
      "GET_VOLUME and GET_FRAME; STATS lists the cascades as the volume does")
def c_plan(ctx):
    c, cfg, t = ctx.scene_session()
    _plan_checks((t.body.get("stats") or {}).get("plan"), "TICK reply stats")
    st = expect_reply(c.request(STATS, {}), STATS).body
    tp = st.get("plan") or {}
    check(tp.get("tick") == t.body.get("tick"), "STATS plan.tick %r, TICK %r" % (tp.get("tick"), t.body.get("tick")))
    v = expect_reply(c.request(GET_VOLUME, {"format": "fp16", "compression": "none"}), GET_VOLUME).body
    _vol_header_checks(v, "fp16", "none")
    n = len(v["cascades"])
    _plan_checks(tp.get("plan"), "STATS plan", cascades=n)
    _plan_checks(v.get("plan"), "GET_VOLUME header", cascades=n)
    cs = tp.get("cascades")
    check(isinstance(cs, list) and len(cs) == n, "STATS plan.cascades %r, the volume has %d" % (cs, n))
    for k, e in enumerate(cs):
        check(e.get("dims") == v["cascades"][k]["dims"]
              and abs(e.get("cell_size_m", 0) - v["cascades"][k]["cell_size"]) <= 1e-6 * v["cascades"][k]["cell_size"],
              "STATS cascade %d %r differs from the volume's %r" % (k, e, v["cascades"][k]))
    expect_reply(c.request(CAMERA_SET, {"eye": [0, 1, 3.5], "target": [0, 1, 0], "fov_deg": 40, "width": 32,
                                        "height": 24}), CAMERA_SET)
    t2 = expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    fr = expect_reply(c.request(GET_FRAME, {"format": "png"}, timeout=ctx.tick_timeout), GET_FRAME).body
    check(fr.get("tick") == t2.body.get("tick"), "GET_FRAME tick %r, TICK %r" % (fr.get("tick"), t2.body.get("tick")))
    _plan_checks(fr.get("plan"), "GET_FRAME header")
    run = [p["name"] for p in tp["plan"]["passes"] if p["run"]]
    return "%d cascade(s); passes run: %s" % (n, ", ".join(run) if run else "none")


@case("R8.1 R4.13 R5.14", "technique iv's tick: its passes (iv_points, iv_reproject, iv_gather, iv_ao) after R8.1's "
      "with their reasons (the bounces asked for, the camera), and the TICK and STATS stats count its volume")
def c_plan_iv(ctx):
    if "iv" not in _iv_techniques(ctx):
        raise Skip("HELLO lists no \"iv\"")
    c, cfg, t = ctx.scene_session(config=dict(IV_CONFIG, iv_bounces=3), light=unique_light("iv-plan"))
    plan = (t.body.get("stats") or {}).get("plan")
    _plan_checks(plan, "TICK reply stats", cascades=1)
    passes = {p["name"]: p for p in plan["passes"]}
    names = [p["name"] for p in plan["passes"]]
    iv_names = ["iv_points", "iv_reproject", "iv_gather", "iv_ao"]
    after = names[len(PLAN_PASSES):len(PLAN_PASSES) + len(iv_names)]
    check(after == iv_names, "passes after R8.1's: %r, expected %r first" % (after, iv_names))
    g = passes["iv_gather"]
    check(g["run"] and "iv: 3 bounces requested" in g["reason"], "iv_gather %r: expected it to run, naming "
          "\"iv: 3 bounces requested\"" % (g,))
    r = passes["iv_reproject"]
    # every lpvd session has a camera (the scene's, CAMERA_SET's or one framing the bounds), so reprojection
    # runs; without one it would be skipped, naming it
    check(r["run"] or "reprojection skipped: no camera" in r["reason"], "iv_reproject %r: expected it to run with "
          "the session's camera, or \"reprojection skipped: no camera\"" % (r,))
    check(not passes["iv_ao"]["run"] and "off" in passes["iv_ao"]["reason"], "iv_ao %r with iv_ao off"
          % (passes["iv_ao"],))
    for k in ("propagate", "inject"):
        check(not passes[k]["run"], "the LPV's pass %r runs for technique iv: %r" % (k, passes[k]))
    st = (t.body.get("stats") or {}).get("iv")
    check(isinstance(st, dict), "TICK stats have no \"iv\" object for technique iv (R4.13): %r" % (st,))
    v = expect_reply(c.request(GET_VOLUME, {"format": "fp16", "compression": "none"}), GET_VOLUME).body
    cells = v["cascades"][0]["cells"]
    check(st.get("points", 0) > 0 and st.get("voxels") == cells and st.get("bounces") == 3
          and st.get("bounces_requested") == 3 and st.get("rays") == IV_CONFIG["iv_rays"]
          and 0 < st.get("occupied", 0) < cells and st.get("ao") is False,
          "TICK stats iv %r: expected points > 0, voxels %d, 3 bounces of 3, %d rays, 0 < occupied < voxels, ao "
          "false" % (st, cells, IV_CONFIG["iv_rays"]))
    # the bounces after the three as a series (iv_tail, on by default): its per-bounce ratio per channel
    ratio = st.get("tail_ratio")
    check(st.get("tail") is True and isinstance(ratio, list) and len(ratio) == 3
          and all(isinstance(x, (int, float)) and 0.0 <= x < 1.0 for x in ratio),
          "TICK stats iv %r: expected tail true and tail_ratio three numbers in [0, 1) (iv_tail on, 3 bounces)"
          % (st,))
    sp = expect_reply(c.request(STATS, {}), STATS).body.get("plan") or {}
    check(sp.get("iv") == st and sp.get("plan") == plan, "STATS plan differs from the TICK reply's stats for the same "
          "tick: iv %r vs %r" % (sp.get("iv"), st))
    expect_reply(c.request(CONFIG, {"iv_reprojection": False, "iv_tail": False}), CONFIG)
    t2 = expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    r2 = {p["name"]: p for p in t2.body["stats"]["plan"]["passes"]}["iv_reproject"]
    check(not r2["run"] and "reprojection off" in r2["reason"], "iv_reproject %r with iv_reprojection false" % (r2,))
    st2 = t2.body["stats"].get("iv") or {}
    check(st2.get("tail") is False and st2.get("tail_ratio") == [0, 0, 0],
          "TICK stats iv %r with iv_tail false: expected tail false and tail_ratio [0, 0, 0]" % (st2,))
    return "iv_gather: %s; iv_reproject: %s / %s; stats %s" % (g["reason"], r["reason"], r2["reason"],
                                                                json.dumps(st, sort_keys=True))
