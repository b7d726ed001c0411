"""conf_config.py - conformance cases: CONFIG: limits, atomicity, presets, techniques, the
knobs HELLO describes, value ranges (R4.6, R4.6a, R4.10 - R4.15)."""

import json

from conf_wire import CAMERA_SET, CONFIG, ERROR, GET_VOLUME, LIGHT_SET, SCENE_UPDATE, TICK, type_name
from conf_core import Fail, Skip, case, check, check_error_shape, expect_error, expect_reply, unique_light


# ---------------------------------------------------------------------------
# Cases: CONFIG limits


@case("R4.6", "CONFIG grid over --max-grid gets LIMIT")
def c_limit_grid(ctx):
    c = ctx.session()
    mg = ctx.max_grid()
    n = (mg + 1) if mg else 4096
    rid = c.send(CONFIG, {"grid": [n, n, n]})
    f = c.recv_reply(rid)
    expect_error(f, "LIMIT", rid)
    rid = c.send(CONFIG, {"grid": [8, 8, n]})
    expect_error(c.recv_reply(rid), "LIMIT", rid)
    return "grid %d refused (max_grid %s)" % (n, mg)


@case("R4.6", "CONFIG tick_rate_hz over --max-tick-rate gets LIMIT")
def c_limit_tick_rate(ctx):
    c = ctx.session()
    rid = c.send(CONFIG, {"tick_rate_hz": 1.0e6})
    expect_error(c.recv_reply(rid), "LIMIT", rid)
    return "1e6 Hz refused"


@case("R4.6a", "CONFIG whose tick would cost over the tick budget gets LIMIT naming it; nothing changes")
def c_limit_tick_cost(ctx):
    c = ctx.session()
    budget = (ctx.limits or {}).get("max_tick_cost")
    if not isinstance(budget, int) or budget < 1:
        raise Fail("HELLO limits advertise no integer max_tick_cost (R4.6a)")
    knobs = {k.get("name"): k for k in (ctx.hello_reply or {}).get("knobs", []) if isinstance(k, dict)}
    it_max = knobs.get("iterations", {}).get("max")
    mg = ctx.max_grid() or 32
    g = min(mg, 64)
    if not isinstance(it_max, int) or g ** 3 * it_max <= budget:
        raise Skip("grid %d and the largest iterations (%r) stay within max_tick_cost %d" % (g, it_max, budget))
    before = expect_reply(c.request(CONFIG, {"iterations": 3}), CONFIG).body.get("config", {})
    rid = c.send(CONFIG, {"grid": [g, g, g], "iterations": it_max})
    f = c.recv_reply(rid)
    expect_error(f, "LIMIT", rid)
    msg = f.body.get("message", "")
    check(str(budget) in msg, "the LIMIT message does not name the budget %d: %r" % (budget, msg))
    after = expect_reply(c.request(CONFIG, {}), CONFIG).body.get("config", {})
    check(after.get("grid") == before.get("grid") and after.get("iterations") == 3,
          "the refused CONFIG changed the effective config: %r -> %r" % (before, after))
    return "grid %d x %d iterations refused against %d: %s" % (g, it_max, budget, msg)


@case("R4.6 R2.9", "invalid CONFIG values get BAD_FIELD")
def c_config_invalid(ctx):
    c = ctx.session()
    for body, field in (({"grid": [0, 8, 8]}, "grid"), ({"grid": [-4, 8, 8]}, "grid"),
                        ({"iterations": -1}, "iterations"), ({"bounds": [1, 1, 1, 0, 0, 0]}, "bounds"),
                        ({"bounds": [0, 0, 0]}, "bounds"), ({"tick_rate_hz": -5}, "tick_rate_hz"),
                        ({"indirect_gain": "x"}, "indirect_gain")):
        rid = c.send(CONFIG, body)
        try:
            expect_error(c.recv_reply(rid), "BAD_FIELD", rid, field)
        except Fail as e:
            raise Fail("CONFIG %s: %s" % (json.dumps(body), e))
    return "7 invalid values refused"


@case("R4.6", "a failed CONFIG changes nothing")
def c_config_atomic(ctx):
    c = ctx.session()
    f0 = expect_reply(c.request(CONFIG, {"grid": [12, 12, 12], "iterations": 5}), CONFIG)
    cfg0 = f0.body.get("config")
    check(isinstance(cfg0, dict), "CONFIG reply without \"config\": %r" % f0.body)
    check(cfg0.get("grid") == [12, 12, 12] and cfg0.get("iterations") == 5,
          "effective config %r does not show grid [12,12,12], iterations 5" % cfg0)
    mg = ctx.max_grid()
    n = (mg + 1) if mg else 4096
    for body in ({"iterations": 7, "grid": [n, n, n]}, {"iterations": 7, "grid": [0, 1, 1]},
                 {"grid": [20, 20, 20], "iterations": "x"}):
        f = c.recv_reply(c.send(CONFIG, body))
        check(f.type == ERROR, "CONFIG %s accepted: %r" % (json.dumps(body), f))
    f1 = expect_reply(c.request(CONFIG, {}), CONFIG)
    cfg1 = f1.body.get("config")
    check(cfg1 == cfg0, "config changed by failed CONFIGs: %r -> %r" % (cfg0, cfg1))
    rev0, rev1 = f0.body.get("revision"), f1.body.get("revision")
    return "config unchanged (revision %r -> %r)" % (rev0, rev1)


def _preset_config(c, body):
    f = expect_reply(c.request(CONFIG, body), CONFIG, what="CONFIG %s" % json.dumps(body))
    cfg = f.body.get("config")
    check(isinstance(cfg, dict), "CONFIG reply without \"config\": %r" % f.body)
    return cfg


@case("R4.10", "CONFIG preset sets grid, iterations, rsm_size, occlusion; other fields override it")
def c_config_preset(ctx):
    c = ctx.session()
    _preset_config(c, {"grid": [12, 12, 12], "iterations": 5, "occlusion": False})
    cfgs = {}
    for name in ("fast", "balanced", "accurate"):
        cfg = _preset_config(c, {"preset": name})
        check(cfg.get("preset") == name,
              "CONFIG preset %r: effective config names preset %r" % (name, cfg.get("preset")))
        check(cfg.get("grid") != [12, 12, 12] or cfg.get("iterations") != 5 or cfg.get("occlusion") is not False,
              "CONFIG preset %r left the explicit grid/iterations/occlusion in place: %r" % (name, cfg))
        cfgs[name] = cfg
    knobs = ("grid", "iterations", "rsm_size", "occlusion")
    fast, acc = [tuple(json.dumps(cfgs[n].get(k)) for k in knobs) for n in ("fast", "accurate")]
    check(fast != acc, "presets fast and accurate give the same grid/iterations/rsm_size/occlusion: %r" % (fast,))
    again = _preset_config(c, {"preset": "fast"})
    check(again == cfgs["fast"], "CONFIG preset fast twice differs: %r vs %r" % (cfgs["fast"], again))
    over = _preset_config(c, {"preset": "accurate", "iterations": 3, "grid": [10, 10, 10]})
    check(over.get("iterations") == 3 and over.get("grid") == [10, 10, 10],
          "fields next to preset do not override it: %r" % over)
    check(over.get("rsm_size") == cfgs["accurate"].get("rsm_size") and over.get("preset") == "accurate",
          "preset accurate with overrides lost its other values: %r" % over)
    keep = _preset_config(c, {"indirect_gain": 2.0})
    check(keep.get("preset") == "accurate" and keep.get("iterations") == 3,
          "a later CONFIG without preset changed the preset or its overrides: %r" % keep)
    return "fast grid %s it %s, accurate grid %s it %s; overrides win" % (
        cfgs["fast"].get("grid"), cfgs["fast"].get("iterations"), cfgs["accurate"].get("grid"),
        cfgs["accurate"].get("iterations"))


@case("R4.10 R4.6 R2.9", "CONFIG with an unknown preset gets BAD_FIELD naming preset and changes nothing")
def c_config_preset_bad(ctx):
    c = ctx.session()
    cfg0 = _preset_config(c, {"grid": [12, 12, 12], "iterations": 5})
    for body in ({"preset": "ultra"}, {"preset": "Fast"}, {"preset": ""}, {"preset": 1}, {"preset": None},
                 {"preset": "fast", "iterations": 5, "grid": [12, 12, 12], "x": 0, "occlusion": "yes"}):
        rid = c.send(CONFIG, body)
        f = c.recv_reply(rid)
        field = "occlusion" if "occlusion" in body else "preset"
        try:
            expect_error(f, "BAD_FIELD", rid, field)
        except Fail as e:
            raise Fail("CONFIG %s: %s" % (json.dumps(body), e))
    cfg1 = _preset_config(c, {})
    check(cfg1 == cfg0, "config changed by refused presets: %r -> %r" % (cfg0, cfg1))
    return "6 CONFIGs with a bad preset (or a bad field next to a good one) refused, config unchanged"


@case("R4.14 R4.6 R2.9", "CONFIG technique takes each technique HELLO lists, reports it, and refuses any other "
      "naming technique")
def c_config_technique(ctx):
    c, _, _ = ctx.scene_session(light=unique_light("tech"))  # its HELLO reply is the one read below
    techniques = ctx.hello_reply.get("techniques")
    check(isinstance(techniques, list) and techniques and all(isinstance(t, str) and t for t in techniques),
          "R4.14: HELLO reply has no non-empty \"techniques\" array of names: %r" % (techniques,))
    cfg0 = _preset_config(c, {})
    check(cfg0.get("technique") in techniques,
          "R4.14: the effective config's technique %r is not one of %r" % (cfg0.get("technique"), techniques))
    said = []
    for t in techniques:
        cfg = _preset_config(c, {"technique": t})
        check(cfg.get("technique") == t, "CONFIG technique %r: effective config says %r" % (t, cfg.get("technique")))
        tk = expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
        v = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
        made_by = (v.body.get("volume") or {}).get("technique")
        if t == "auto":  # R4.14: the server chooses one of the others and the plan says why
            plan = v.body.get("plan") or {}
            check(made_by in techniques and made_by != "auto",
                  "R4.14/R5.9: after CONFIG technique auto the volume says technique %r" % (made_by,))
            check(plan.get("technique") == made_by and isinstance(plan.get("technique_reason"), str)
                  and plan["technique_reason"].startswith("auto"),
                  "R4.14/R8.1: technique auto: the plan says %r / %r" % (plan.get("technique"),
                                                                      plan.get("technique_reason")))
        else:
            check(made_by == t, "R4.14/R5.9: after CONFIG technique %r the volume says technique %r" % (t, made_by))
        said.append("%s (tick %s)" % (t, tk.body.get("tick")))
    cfg1 = _preset_config(c, {})
    for body in ({"technique": "photon_mapping"}, {"technique": ""}, {"technique": 1}, {"technique": None},
                 {"technique": techniques[0].upper() + "_"}):
        rid = c.send(CONFIG, body)
        try:
            expect_error(c.recv_reply(rid), "BAD_FIELD", rid, "technique")
        except Fail as e:
            raise Fail("CONFIG %s: %s" % (json.dumps(body), e))
    check(_preset_config(c, {}) == cfg1, "a refused technique changed the config")
    return "chosen and ticked: %s; 5 bad names refused" % ", ".join(said)


# R4.12: the knobs are the server's own description (HELLO "knobs"), not a
# list kept here; these cases check that the description is true: what it
# says CONFIG accepts, CONFIG accepts, and what it says is out of range or of
# the wrong type, CONFIG refuses naming the knob.
KNOB_TYPES = ("int", "number", "bool")
KNOB_TOUCHES = ["volume", "samples", "shadows", "shading"]


def _knobs(ctx):
    """A fresh session and the server's knob description, checked for shape (R4.12)."""
    c = ctx.session()
    knobs = ctx.hello_reply.get("knobs")
    check(isinstance(knobs, list) and knobs, "R4.12: HELLO reply has no non-empty \"knobs\" array: %r"
          % (ctx.hello_reply,))
    names = set()
    for k in knobs:
        check(isinstance(k, dict) and isinstance(k.get("name"), str) and k["name"], "R4.12: knob without a name: %r" % (k,))
        check(k["name"] not in names, "R4.12: knob %r described twice" % k["name"])
        names.add(k["name"])
        check(k.get("type") in KNOB_TYPES, "R4.12: knob %s has type %r, expected one of %r" % (k["name"],
                                                                                           k.get("type"), KNOB_TYPES))
        for key in ("default_text", "unit", "note", "help"):
            check(isinstance(k.get(key), str), "R4.12: knob %s has no string %r" % (k["name"], key))
        check(_same(k["type"], k.get("default"), k.get("default")),
              "R4.12: knob %s: default %r is not a %s" % (k["name"], k.get("default"), k["type"]))
        if k["type"] != "bool":
            lo, hi = k.get("min"), k.get("max")
            check(_same(k["type"], lo, lo) and _same(k["type"], hi, hi) and lo <= hi,
                  "R4.12: knob %s: min %r / max %r are not %ss with min <= max" % (k["name"], lo, hi, k["type"]))
            check(isinstance(k.get("min_exclusive"), bool), "R4.12: knob %s has no boolean min_exclusive" % k["name"])
        check(isinstance(k.get("technique"), str), "R4.12: knob %s has no string technique" % k["name"])
        t = k.get("touches")
        check(isinstance(t, list) and t and all(x in KNOB_TOUCHES for x in t)
              and t == sorted(t, key=KNOB_TOUCHES.index),
              "R4.12: knob %s: touches %r is not a non-empty subset of %r in that order" % (k["name"], t, KNOB_TOUCHES))
    presets = ctx.hello_reply.get("presets")
    check(isinstance(presets, list) and presets and all(isinstance(p, str) for p in presets),
          "R4.12: HELLO reply has no non-empty \"presets\" array of names: %r" % (presets,))
    return c, knobs, presets


def _in_range(k):
    """Values the description allows: the default, both ends (min only when inclusive), the middle."""
    if k["type"] == "bool":
        return [True, False, k["default"]]
    lo, hi = k["min"], k["max"]
    mid = (lo + hi) / 2.0
    if k["type"] == "int":
        mid = int(mid)
    vals = [k["default"], hi, mid] + ([] if k["min_exclusive"] else [lo])
    return [v for v in vals if (v > lo or (v == lo and not k["min_exclusive"])) and v <= hi]


def _out_of_range(k):
    if k["type"] == "bool":
        return []
    lo, hi = k["min"], k["max"]
    if k["type"] == "int":
        return [hi + 1] + ([lo] if k["min_exclusive"] else [lo - 1])
    return [hi + 0.5 * max(1.0, abs(hi))] + ([lo] if k["min_exclusive"] else [lo - 0.5 * max(1.0, abs(lo))])


WRONG_TYPES = {"int": (1.5, 2.0, "1", True),  # 2.0: a JSON number, not a JSON integer (R4.11)
               "number": ("1", True, [1]), "bool": (1, "on", None)}


def _same(kind, got, want):
    if kind == "bool":
        return got is want
    if kind == "int":
        return type(got) is int and got == want
    return isinstance(got, (int, float)) and not isinstance(got, bool) and abs(got - want) <= 1e-6 * max(1, abs(want))


@case("R4.12 R4.11", "HELLO describes every knob of the effective config with its type, range and default")
def c_knob_description(ctx):
    c, knobs, presets = _knobs(ctx)
    cfg = _preset_config(c, {})
    for k in knobs:
        check(k["name"] in cfg, "R4.12: described knob %s is not in the effective config %r" % (k["name"], cfg))
        check(_same(k["type"], cfg[k["name"]], k["default"]),
              "R4.12: effective %s is %r, the description's default is %r" % (k["name"], cfg[k["name"]], k["default"]))
    check(cfg.get("preset") in presets, "effective preset %r is not one of the described %r" % (cfg.get("preset"), presets))
    for p in presets:
        _preset_config(c, {"preset": p})
    return "%d knobs, %d presets (%s)" % (len(knobs), len(presets), ", ".join(presets))


@case("R4.12 R4.13", "a knob that touches only the shading leaves the next TICK's volume as it was; one that "
      "touches the volume recomputes it")
def c_knob_touches(ctx):
    c, knobs, _ = _knobs(ctx)
    shading = [k for k in knobs if k["touches"] == ["shading"] and k["type"] != "bool"]
    volume = [k for k in knobs if "volume" in k["touches"] and k["type"] == "int" and k["name"] == "iterations"]
    check(shading, "R4.12: no number knob touches only the shading")
    c, _, _ = ctx.scene_session(light=unique_light("touch"))
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    a = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    k = shading[0]
    v = k["max"] if k["max"] != k["default"] else k["min"]
    _preset_config(c, {k["name"]: v})
    t = expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    plan = (t.body.get("stats") or {}).get("plan") or {}
    check(plan.get("recompute") is False,
          "CONFIG %s touches only the shading, yet the TICK recomputed: %r" % (k["name"], plan.get("recompute_reason")))
    b = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    check(b.att == a.att, "CONFIG %s (touches shading only) changed the volume" % k["name"])
    said = "%s -> cached volume (%s)" % (k["name"], plan.get("recompute_reason"))
    if volume:
        k = volume[0]
        _preset_config(c, {k["name"]: k["default"] + 1 if k["default"] < k["max"] else k["default"] - 1})
        t = expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
        plan = (t.body.get("stats") or {}).get("plan") or {}
        check(plan.get("recompute") is True, "CONFIG %s touches the volume, yet the TICK served the cached one"
              % k["name"])
        said += "; %s -> %s" % (k["name"], plan.get("recompute_reason"))
    return said


@case("R4.12 R4.11", "CONFIG accepts every described knob across its described range and echoes it resolved")
def c_config_knobs(ctx):
    c, knobs, presets = _knobs(ctx)
    # technique lpv named, as the session was before issue 30 made lpvd's default "auto": every knob of another
    # technique is then accepted and kept without effect (R4.14), so its whole described range can be echoed. With
    # auto or iv the imperfect volume's cost counts, and iv_resolution 256 at the default 128 rays is over lpvd's
    # default tick budget: LIMIT (R4.6a), whatever the description's max says
    _preset_config(c, {"technique": "lpv"})
    n = 0
    for k in knobs:
        for v in _in_range(k):
            cfg = _preset_config(c, {k["name"]: v})
            check(_same(k["type"], cfg.get(k["name"]), v),
                  "CONFIG {%r: %r}: effective config says %r" % (k["name"], v, cfg.get(k["name"])))
            n += 1
    # every knob at once, next to a preset: each one's value wins over the preset's. The middle of each range
    # (the maximum for booleans' index): every knob at its maximum together may not fit one world (rsm_size and
    # shadow_size at their ends need more than lpvd's default --max-world-memory), which R4.6a lets a server refuse
    both = {k["name"]: _in_range(k)[2 if k["type"] != "bool" and len(_in_range(k)) > 2 else 1] for k in knobs}
    both["preset"] = presets[0]
    cfg = _preset_config(c, both)
    for k in knobs:
        check(_same(k["type"], cfg.get(k["name"]), both[k["name"]]),
              "CONFIG %s: %s is %r" % (json.dumps(both), k["name"], cfg.get(k["name"])))
    check(cfg.get("preset") == presets[0], "preset next to the knobs lost: %r" % cfg)
    return "%d knobs, %d values echoed" % (len(knobs), n)


@case("R4.12 R4.11 R4.6 R2.9", "out-of-range and wrongly typed knob values are refused naming the knob; nothing changes")
def c_config_knobs_bad(ctx):
    c, knobs, _ = _knobs(ctx)
    cfg0 = _preset_config(c, {})
    n = 0
    for k in knobs:
        for v, names in [(v, ("BAD_FIELD", "LIMIT")) for v in _out_of_range(k)] + \
                        [(v, ("BAD_FIELD",)) for v in WRONG_TYPES[k["type"]]]:
            body = {k["name"]: v}
            rid = c.send(CONFIG, body)
            f = c.recv_reply(rid)
            check(f.type == ERROR, "CONFIG %s: accepted, expected %s" % (json.dumps(body), " or ".join(names)))
            check_error_shape(f)
            check(f.body["name"] in names, "CONFIG %s: ERROR %s, expected %s" % (json.dumps(body), f.body["name"],
                                                                                  " or ".join(names)))
            check(k["name"] in f.body["message"], "CONFIG %s: message %r does not name the knob (R2.9)"
                  % (json.dumps(body), f.body["message"]))
            n += 1
    cfg1 = _preset_config(c, {})
    check(cfg1 == cfg0, "config changed by refused knob values: %r -> %r" % (cfg0, cfg1))
    return "%d bad values refused, config unchanged" % n


@case("R4.15", "every value accepted can be ticked with: values where float math breaks are refused naming the "
      "field, values inside the ranges tick")
def c_value_ranges(ctx):
    light = {"id": "r", "type": "point", "position": [0.1, 0.6, 0.2], "intensity": 5}
    c, _, _ = ctx.scene_session(light=light)
    refused = [  # (type, body, field the message must name)
        (CAMERA_SET, {"eye": [0, 0, 1e19], "target": [0, 0, -1e19]}, "eye"),
        (CAMERA_SET, {"eye": [0, 0, 3], "target": [0, 0, 3]}, "target"),
        (LIGHT_SET, dict(light, intensity=1e30, color=[1e30, 1e30, 1e30]), "intensity"),
        (LIGHT_SET, dict(light, position=[1e30, 0, 0]), "position"),
        (CONFIG, {"bounds": [-1e30, -1e30, -1e30, 1e30, 1e30, 1e30]}, "bounds"),
        (CONFIG, {"cascades": 3, "cascade_size": 1e-30}, "cascade_size"),
        (SCENE_UPDATE, {"nodes": [{"node": 0, "scale": [1e30, 1e30, 1e30]}]}, "nodes"),
    ]
    for t, body, field in refused:
        f = c.request(t, body, timeout=ctx.tick_timeout)
        expect_error(f, "BAD_FIELD", field=field)
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK, what="TICK after the refusals")
    accepted = [
        (CAMERA_SET, {"eye": [0, 0.5, 3], "target": [0, 0.5, 0], "fov_deg": 179}),
        (LIGHT_SET, dict(light, intensity=1e30)),
        (CONFIG, {"cascades": 3, "cascade_size": 0.5}),
        (CONFIG, {"cascades": 0, "cascade_size": 1e-30}),  # the planner's choice: one grid when it must
        (CONFIG, {"bounds": [-1e9, -1e9, -1e9, 1e9, 1e9, 1e9]}),  # last: given bounds stay
    ]
    for t, body in accepted:
        expect_reply(c.request(t, body, timeout=ctx.tick_timeout), t, what="%s %s" % (type_name(t), json.dumps(body)))
        expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK,
                     what="TICK after %s %s" % (type_name(t), json.dumps(body)))
    return "%d values refused naming the field, %d accepted and ticked" % (len(refused), len(accepted))
