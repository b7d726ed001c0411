"""conf_volumes.py - conformance cases: volumes from GET_VOLUME: the description, octree levels,
technique iv, technique probes' visibility, layout, fp16, zstd, dims, and compression shq's
codecs, bound and refusals (R5.1 - R5.16)."""

import math
import os
import random
import struct

from conf_wire import (
    CONFIG, GET_VOLUME, LIGHT_SET, QUERY_IRRADIANCE, SCENE_LOAD, SUBSCRIBE, TICK, UNSUBSCRIBE, VOLUME)
from conf_payloads import (
    SMALL_CONFIG, box_scene_glb, f16_list, f32_list, zstd_decompress_cli, zstd_frame_content_size)
from conf_core import Fail, case, check, expect_error, expect_reply, is_finite_list, unique_light
from conf_volume_checks import (
    IV_CONFIG, IV_VOXELS_ROLE, PROBES_CONFIG, SH_LOBE0, SH_LOBE1, SHQ_CODECS, _description_checks, _iv_levels,
    _iv_lookup, _iv_techniques, _octree_levels, _probes_lookup, _shq_bound_checks, _shq_decode, _vol_header_checks)


# ---------------------------------------------------------------------------
# Cases: volumes


@case("R5.9", "GET_VOLUME and VOLUME headers carry a versioned \"volume\" description naming the technique")
def c_volume_description(ctx):
    c, cfg, t = ctx.scene_session()
    seen = []
    for fmt in ("fp32", "fp16"):
        f = expect_reply(c.request(GET_VOLUME, {"format": fmt, "compression": "none"}), GET_VOLUME)
        _vol_header_checks(f.body, fmt, "none")
        check(len(f.att) == f.body["raw_length"], "attachment %d bytes, raw_length %d" % (len(f.att),
                                                                                        f.body["raw_length"]))
        seen.append(f.body["volume"])
    expect_reply(c.request(SUBSCRIBE, {"stream": "volume", "format": "fp32", "compression": "none"}), SUBSCRIBE)
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    v = c.recv_stream(VOLUME, timeout=ctx.tick_timeout)
    _vol_header_checks(v.body, "fp32", "none")
    # the description says what the cells are, not how they are sent
    check(v.body["volume"] == seen[0] == seen[1], "the description differs between fp32, fp16 and the stream: %r"
          % ([seen[0], seen[1], v.body["volume"]],))
    d = seen[0]
    return "layout %d, technique %s, %d values x %d volume(s) per cell" % (
        d["layout_version"], d["technique"], d["values_per_cell"], d["volumes_per_level"])


@case("R5.10", "the description's levels are the cascades (placement) with roles that agree with far_field")
def c_volume_description_levels(ctx):
    out = []
    for ff in (False, True):
        c, cfg, t = ctx.scene_session(config=dict(SMALL_CONFIG, far_field=ff))
        f = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
        _vol_header_checks(f.body, "fp32", "none")
        d = f.body["volume"]
        check(d["far_field"] == ff, "CONFIG far_field %r, the description says far_field %r" % (ff, d["far_field"]))
        out.append("far_field %s: %s" % (ff, [lv["role"] for lv in d["levels"]]))
        c.close()
    return "; ".join(out)


@case("R5.11 R5.1", "values per cell are named (values_per_cell names) and drive raw_length; the 12 SH values "
      "agree with the legacy layout")
def c_volume_description_values(ctx):
    c, cfg, t = ctx.scene_session()
    f = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    d = _description_checks(f.body)
    vpc, vpl = d["values_per_cell"], d["volumes_per_level"]
    cells = sum(cc["cells"] for cc in f.body["cascades"])
    check(len(f.att) == cells * vpl * vpc * 4, "attachment %d bytes, the description gives %d cells x %d x %d x 4"
          % (len(f.att), cells, vpl, vpc))
    # R5.1's legacy keys describe 12 values per cell r0..r3 g0..g3 b0..b3 in
    # one volume per level: a description of them must say the same count
    # with one name per channel and coefficient, channel-major.
    if "layout" in f.body:
        check(vpc == 12 and vpl == 1, "legacy \"layout\" %r sent, but the description has %d values x %d volumes"
              % (f.body["layout"], vpc, vpl))
        chans = [v.split(".", 1)[0] for v in d["values"]]
        check(chans == [chans[0]] * 4 + [chans[4]] * 4 + [chans[8]] * 4 and len(set(chans)) == 3,
              "values %r are not 4 per channel, channel-major, as the layout %r" % (d["values"], f.body["layout"]))
    return "%d values: %s" % (vpc, ", ".join(d["values"]))


@case("R5.13 R5.12", "GET_VOLUME content levels with technique octree: every octree level placed as described, an "
      "index of one level per cell, and the merged volume is the indexed levels (eq. 10); refused for lpv")
def c_volume_octree_levels(ctx):
    ctx.session().close()  # its HELLO reply lists the techniques
    techniques = (ctx.hello_reply or {}).get("techniques") or []
    if "octree" not in techniques:  # no technique with levels: "levels" is refused (R5.13)
        c, cfg, t = ctx.scene_session(light=unique_light("no-octree-levels"))
        rid = c.send(GET_VOLUME, {"format": "fp32", "content": "levels"})
        expect_error(c.recv_reply(rid), "BAD_FIELD", rid, "content")
        return "HELLO lists no \"octree\" (%r): content \"levels\" refused naming content" % (techniques,)
    n = 8
    # one step: light spreads a cell on level 0, so coarser levels fill the rest (eq. 10 picks them)
    config = dict(SMALL_CONFIG, grid=[n, n, n], technique="octree", iterations=1)
    c, cfg, t = ctx.scene_session(config=config, light=unique_light("octree-levels"))
    for body in ({"content": "everything"}, {"content": 1}):
        rid = c.send(GET_VOLUME, dict(body, format="fp32"))
        expect_error(c.recv_reply(rid), "BAD_FIELD", rid, "content")
    m = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none", "content": "merged"}),
                     GET_VOLUME)
    plain = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    check(m.att == plain.att, "content \"merged\" differs from GET_VOLUME without content (the default)")
    _vol_header_checks(m.body, "fp32", "none", [n, n, n])
    check(not _octree_levels(m.body["volume"]), "content \"merged\" describes octree levels")
    f = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none", "content": "levels"}),
                     GET_VOLUME)
    _vol_header_checks(f.body, "fp32", "none", [n, n, n])
    d = f.body["volume"]
    check(d["technique"] == "octree", "content levels from technique %r" % (d["technique"],))
    check(_octree_levels(d), "content \"levels\" with technique octree: levels %r are not octree levels"
          % ([lv.get("role") for lv in d["levels"]],))
    check(len(f.att) == f.body["raw_length"], "attachment %d bytes, raw_length %d" % (len(f.att),
                                                                                    f.body["raw_length"]))
    check(f.body["tick"] == m.body["tick"], "levels of tick %r, merged of tick %r" % (f.body["tick"],
                                                                                      m.body["tick"]))
    z = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "zstd", "content": "levels"}),
                     GET_VOLUME)
    zs = zstd_frame_content_size(z.att)
    check(zs[0] and zs[1] == f.body["raw_length"], "zstd levels: content size %r (%s), raw_length %d"
          % (zs[1], zs[2], f.body["raw_length"]))
    l = len(d["levels"])
    ix = d["index"]
    index = struct.unpack("<%dI" % (n ** 3), f.att[ix["raw_offset"]:ix["raw_offset"] + ix["raw_length"]])
    vals = f32_list(f.att[:ix["raw_offset"]])
    check(is_finite_list(vals), "non-finite values in the levels")
    first, at = [], 0
    for lv in d["levels"]:
        first.append(at)
        at += lv["cells"] * 12
    merged = f32_list(m.att)
    used = [0] * l
    for z_ in range(n):
        for y in range(n):
            for x in range(n):
                cell = x + n * (y + n * z_)
                i = index[cell]
                check(0 <= i < l, "index[%d] = %d, not a level in 0..%d" % (cell, i, l - 1))
                used[i] += 1
                k = n >> i
                src = first[i] + 12 * ((x >> i) + k * ((y >> i) + k * (z_ >> i)))
                got, want = merged[12 * cell:12 * cell + 12], vals[src:src + 12]
                check(got == want, "merged cell (%d, %d, %d) %r is not level %d's cell at x >> %d %r (eq. 10)"
                      % (x, y, z_, got[:4], i, i, want[:4]))
                if i < l - 1:
                    check(any(v != 0.0 for v in want), "index[%d] = %d names a level with no light there" % (cell, i))
    check(any(v != 0.0 for v in merged[0::4]), "the merged volume of a lit box is all zero")
    check(sum(used[1:]) > 0, "after one step every cell's light is level 0's (%r): eq. 10 is not exercised" % (used,))
    # a technique without levels: content "levels" is refused naming content
    expect_reply(c.request(CONFIG, {"technique": "lpv"}), CONFIG)
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    rid = c.send(GET_VOLUME, {"format": "fp32", "content": "levels"})
    expect_error(c.recv_reply(rid), "BAD_FIELD", rid, "content")
    return "%d levels (%s), %d bytes; cells per index level %r; merged = the indexed levels; lpv refused" % (
        l, ", ".join("%d^3" % lv["dims"][0] for lv in d["levels"]), len(f.att), used)


@case("R5.14 R5.12 R4.7", "technique iv: GET_VOLUME and VOLUME describe one \"iv_voxels\" level in W/(m^2 sr) with "
      "the occupancy index and the effective iv_neighbours; R5.14's lookup on it agrees with QUERY_IRRADIANCE")
def c_volume_iv(ctx):
    if "iv" not in _iv_techniques(ctx):
        c = ctx.session()
        rid = c.send(CONFIG, {"technique": "iv"})
        expect_error(c.recv_reply(rid), "BAD_FIELD", rid, "technique")
        return "HELLO lists no \"iv\": CONFIG technique iv refused naming technique (R4.14)"
    c, cfg, t = ctx.scene_session(config=dict(IV_CONFIG, iv_neighbours=6), light=unique_light("iv-volume"))
    nb = (cfg.body.get("config") or {}).get("iv_neighbours")
    check(nb == 6, "CONFIG iv_neighbours 6: the effective config says %r" % (nb,))
    f = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    h = f.body
    _vol_header_checks(h, "fp32", "none")
    d = h["volume"]
    check(_iv_levels(d), "technique iv's volume has levels %r, expected one %r level (R5.14)"
          % ([lv.get("role") for lv in d.get("levels") or []], IV_VOXELS_ROLE))
    check(d["technique"] == "iv", "volume.technique %r, expected iv" % (d["technique"],))
    check(d["iv_neighbours"] == nb, "volume.iv_neighbours %r, the effective config's is %r (R5.14)"
          % (d["iv_neighbours"], nb))
    cells = h["cascades"][0]["cells"]
    ix = d["index"]
    check(ix["raw_offset"] == cells * 12 * 4 and ix["raw_length"] == cells * 4
          and h["raw_length"] == cells * 12 * 4 + cells * 4 == len(f.att),
          "raw_length %r, index at %r of %r bytes, attachment %d: expected %d voxels x 48 + %d x 4 (R5.14)"
          % (h["raw_length"], ix["raw_offset"], ix["raw_length"], len(f.att), cells, cells))
    vals = f32_list(f.att[:ix["raw_offset"]])
    held = struct.unpack("<%dI" % cells, f.att[ix["raw_offset"]:])
    check(is_finite_list(vals), "non-finite values in the iv volume")
    check(set(held) <= {0, 1}, "index entries %r: R5.14 has 1 (holds a surface) or 0" % (sorted(set(held)),))
    check(0 < sum(held) < cells, "%d of %d voxels hold a surface in a box" % (sum(held), cells))
    check(any(v != 0.0 for v in vals[0::4]), "the iv volume of a lit box is all zero")
    st = (t.body.get("stats") or {}).get("iv")
    if isinstance(st, dict) and "occupied" in st:  # R4.13 (informative)
        check(st["occupied"] == sum(held), "TICK stats iv.occupied %r, the index has %d" % (st["occupied"], sum(held)))
    # the same description and index in fp16, zstd and the stream; no "levels" content
    z = expect_reply(c.request(GET_VOLUME, {"format": "fp16", "compression": "zstd"}), GET_VOLUME)
    _vol_header_checks(z.body, "fp16", "zstd")
    check(z.body["volume"]["levels"] == d["levels"] and z.body["volume"]["iv_neighbours"] == nb,
          "fp16/zstd describes other levels than fp32")
    rid = c.send(GET_VOLUME, {"format": "fp32", "content": "levels"})
    expect_error(c.recv_reply(rid), "BAD_FIELD", rid, "content")
    expect_reply(c.request(SUBSCRIBE, {"stream": "volume", "format": "fp32", "compression": "none"}), SUBSCRIBE)
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    v = c.recv_stream(VOLUME, timeout=ctx.tick_timeout)
    _vol_header_checks(v.body, "fp32", "none")
    check(v.body["volume"] == d, "the VOLUME stream describes the iv volume otherwise than GET_VOLUME")
    check(v.att[ix["raw_offset"]:] == f.att[ix["raw_offset"]:], "the streamed index differs (same inputs)")
    expect_reply(c.request(UNSUBSCRIBE, {"stream": "volume"}), UNSUBSCRIBE)
    # R5.14's lookup here against the server's QUERY_IRRADIANCE, at seeded random points (no exact corner ties)
    f = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    vals = f32_list(f.att[:ix["raw_offset"]])
    held = struct.unpack("<%dI" % cells, f.att[ix["raw_offset"]:])
    lv = d["levels"][0]
    rnd = random.Random(14)
    probes = []
    for i in range(90):
        p = [lv["origin"][a] + rnd.uniform(0.03, 0.97) * lv["dims"][a] * lv["cell_size"] for a in range(3)]
        n = [(0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (-1.0, 0.0, 0.0)][i % 3] if i % 2 else \
            [rnd.uniform(-1.0, 1.0) for _ in range(3)]
        probes.append((p, n))
    att = b"".join(struct.pack("<6f", *(p + list(n))) for p, n in probes)
    q = expect_reply(c.request(QUERY_IRRADIANCE, {"count": len(probes)}, att), QUERY_IRRADIANCE)
    check(q.body.get("tick") == f.body.get("tick"), "query tick %r != volume tick %r" % (q.body.get("tick"),
                                                                                       f.body.get("tick")))
    got = f32_list(q.att)
    want = []
    for p, n in probes:
        want.extend(_iv_lookup(d, vals, held, p, n))
    peak = max(max(want), max(got))
    check(peak > 0.0, "every irradiance is zero (the light does not reach the probes?)")
    tol = 1e-4 * peak  # R5.14: about 1e-6 of the peak where no two corners tie
    bad = [(i, a, b) for i, (a, b) in enumerate(zip(want, got)) if abs(a - b) > tol]
    check(not bad, "%d of %d channel values differ by more than %.3g W/m^2, e.g. probe %d channel %d: R5.14's "
          "lookup %.6g, QUERY_IRRADIANCE %.6g" % (len(bad), len(want), tol, bad[0][0] // 3, bad[0][0] % 3,
                                                  bad[0][1], bad[0][2]) if bad else "")
    worst = max(abs(a - b) for a, b in zip(want, got))
    return "%s voxels, %d hold a surface, iv_neighbours %d; %d probes agree with QUERY_IRRADIANCE to %.2e of the " \
        "peak %.4g W/m^2" % ("x".join(str(x) for x in lv["dims"]), sum(held), nb, len(probes), worst / peak, peak)


# the test box's surfaces (conf_payloads.box_scene_glb): a point's range per axis and the surface's normal
BOX_SURFACES = (("floor", ((-1, 1), (0, 0), (-1, 1)), (0.0, 1.0, 0.0)),
                ("ceiling", ((-1, 1), (2, 2), (-1, 1)), (0.0, -1.0, 0.0)),
                ("back wall", ((-1, 1), (0, 2), (-1, -1)), (0.0, 0.0, 1.0)),
                ("left wall", ((-1, -1), (0, 2), (-1, 1)), (1.0, 0.0, 0.0)),
                ("right wall", ((1, 1), (0, 2), (-1, 1)), (-1.0, 0.0, 0.0)))


def _f32_round(x):
    return struct.unpack("<f", struct.pack("<f", x))[0]


BOX_AIR = ((-0.95, 0.95), (0.05, 1.95), (-0.95, 0.95))  # inside the test box, 5 cm from its walls


def _level_air(lv):
    """The part of a level's box inside BOX_AIR (per axis (lo, hi))."""
    return tuple((max(lo, lv["origin"][a]), min(hi, lv["origin"][a] + lv["dims"][a] * lv["cell_size"]))
                 for a, (lo, hi) in enumerate(BOX_AIR))


def _block_surfaces(block):
    """A closed block's faces as BOX_SURFACES has the box's."""
    (x0, y0, z0), (x1, y1, z1) = block
    return (("block top", ((x0, x1), (y1, y1), (z0, z1)), (0.0, 1.0, 0.0)),
            ("block bottom", ((x0, x1), (y0, y0), (z0, z1)), (0.0, -1.0, 0.0)),
            ("block front", ((x0, x1), (y0, y1), (z1, z1)), (0.0, 0.0, 1.0)),
            ("block back", ((x0, x1), (y0, y1), (z0, z0)), (0.0, 0.0, -1.0)),
            ("block left", ((x0, x0), (y0, y1), (z0, z1)), (-1.0, 0.0, 0.0)),
            ("block right", ((x1, x1), (y0, y1), (z0, z1)), (1.0, 0.0, 0.0)))


def _probes_points(seed, surface_points, air, surfaces=BOX_SURFACES):
    """Seeded points on the surfaces (by default the box's) with their
    normals, and points in the air with random unit normals (air: [(count,
    box per axis (lo, hi))]), as binary32 (what QUERY_IRRADIANCE carries)."""
    rnd = random.Random(seed)
    out = []
    for i in range(surface_points):
        _, rng, n = surfaces[i % len(surfaces)]
        p = [lo if lo == hi else rnd.uniform(lo + 0.02 * (hi - lo), hi - 0.02 * (hi - lo)) for lo, hi in rng]
        out.append(([_f32_round(x) for x in p], list(n)))
    for count, box in air:
        for _ in range(count):
            out.append(([_f32_round(rnd.uniform(lo, hi)) for lo, hi in box], _random_unit(rnd)))
    return out


def _random_unit(rnd):
    """A random unit normal, in binary32."""
    while True:
        n = [rnd.gauss(0.0, 1.0) for _ in range(3)]
        ln = math.sqrt(sum(x * x for x in n))
        if ln > 0.1:
            return [_f32_round(x / ln) for x in n]


def _probes_lookup_vs_query(ctx, c, seed, surface_points=60, air_points=30, more_surfaces=()):
    """R5.15's lookup (the suite's, from the SPEC) on a GET_VOLUME content
    "visibility" against QUERY_IRRADIANCE of the same tick, at points on the
    box's surfaces and in its air (as many in each level's box): at least
    90 % of the points within 1e-4 of the largest irradiance (the SPEC's
    "about 1e-4, except near the thresholds"), every point within 2e-2 of
    it. Returns a summary."""
    f = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none", "content": "visibility"}),
                     GET_VOLUME, what="GET_VOLUME content visibility")
    _vol_header_checks(f.body, "fp32", "none", visibility=True)
    d = f.body["volume"]
    vis = f32_list(f.att[d["visibility"]["raw_offset"]:])
    boxes = [b for b in (_level_air(lv) for lv in d["levels"]) if all(lo < hi for lo, hi in b)]
    air = [(air_points // len(boxes), b) for b in boxes] if boxes else [(air_points, BOX_AIR)]
    pts = _probes_points(seed, surface_points, air, BOX_SURFACES + tuple(more_surfaces))
    # R5.15: n / |n| whatever its length, and E = 0 without one (|n| <= 1e-8)
    pts += [(p, [_f32_round(x * k) for x in n]) for (p, n), k in zip(pts[:8], (3.0, 0.25) * 4)]
    pts += [(pts[0][0], [0.0, 0.0, 0.0]), (pts[1][0], [0.0, 1e-9, 0.0])]
    att = b"".join(struct.pack("<6f", *(p + n)) for p, n in pts)
    q = expect_reply(c.request(QUERY_IRRADIANCE, {"count": len(pts)}, att), QUERY_IRRADIANCE)
    check(q.body.get("tick") == f.body.get("tick"), "query tick %r != volume tick %r" % (q.body.get("tick"),
                                                                                       f.body.get("tick")))
    got = f32_list(q.att)
    stats = {}
    want = []
    for p, n in pts:
        want.extend(_probes_lookup(d, vis, p, n, stats))
    check(is_finite_list(want), "R5.15's lookup gave a non-finite irradiance")
    peak = max(max(want), max(got))
    check(peak > 0.0, "every irradiance is zero (the light does not reach the points?)")
    errs = [max(abs(want[3 * i + ch] - got[3 * i + ch]) for ch in range(3)) for i in range(len(pts))]
    close = sum(1 for e in errs if e <= 1e-4 * peak)
    worst = max(range(len(pts)), key=lambda i: errs[i])
    detail = "the worst, point %d %r facing %r: R5.15's lookup %r, QUERY_IRRADIANCE %r" % (
        worst, pts[worst][0], pts[worst][1], ["%.6g" % x for x in want[3 * worst:3 * worst + 3]],
        ["%.6g" % x for x in got[3 * worst:3 * worst + 3]])
    check(got[-6:] == (0.0,) * 6, "QUERY_IRRADIANCE %r at normals (0, 0, 0) and (0, 1e-9, 0): R5.15 says 0"
          % (got[-6:],))
    check(close >= 0.9 * len(pts), "%d of %d points agree with QUERY_IRRADIANCE within 1e-4 of the peak %.4g W/m^2 "
          "(R5.15: about 1e-4 except near the thresholds; 90 %% asked); %s" % (close, len(pts), peak, detail))
    check(errs[worst] <= 2e-2 * peak, "a point differs by %.3g of the peak %.4g W/m^2 (more than a threshold's "
          "flip explains; 2e-2 allowed); %s" % (errs[worst] / peak, peak, detail))
    return "%d of %d points within 1e-4 of the peak %.4g W/m^2, the worst %.2e (the lookup met %s)" % (
        close, len(pts), peak, errs[worst] / peak, ", ".join("%s %d" % kv for kv in sorted(stats.items())) or
        "no threshold")


@case("R5.15 R5.2 R4.7", "technique probes: GET_VOLUME content visibility (fp32, fp16, zstd) is the merged "
      "volume plus the probes' visibility as described; its values in range; not on the stream; R5.15's lookup "
      "agrees with QUERY_IRRADIANCE; refused for lpv")
def c_volume_probes_visibility(ctx):
    if "probes" not in _iv_techniques(ctx):  # no technique probes: content "visibility" is refused (R5.15)
        c, cfg, t = ctx.scene_session(light=unique_light("no-probes"))
        rid = c.send(GET_VOLUME, {"format": "fp32", "content": "visibility"})
        expect_error(c.recv_reply(rid), "BAD_FIELD", rid, "content")
        return "HELLO lists no \"probes\": content \"visibility\" refused naming content"
    c, cfg, t = ctx.scene_session(config=PROBES_CONFIG, light=unique_light("probes-visibility"))
    check((cfg.body.get("config") or {}).get("technique") == "probes", "CONFIG technique probes: the effective "
          "config says %r" % ((cfg.body.get("config") or {}).get("technique"),))
    seen, notes = {}, []
    for fmt in ("fp32", "fp16"):
        f = expect_reply(c.request(GET_VOLUME, {"format": fmt, "compression": "none", "content": "visibility"}),
                         GET_VOLUME, what="GET_VOLUME %s content visibility" % fmt)
        m = expect_reply(c.request(GET_VOLUME, {"format": fmt, "compression": "none"}), GET_VOLUME)
        h = f.body
        _vol_header_checks(h, fmt, "none", PROBES_CONFIG["grid"], visibility=True)
        _vol_header_checks(m.body, fmt, "none", PROBES_CONFIG["grid"])
        d = h["volume"]
        vd = d["visibility"]
        check(d["technique"] == "probes", "volume.technique %r, expected probes" % (d["technique"],))
        check(h["keyframe"] is True, "content visibility keyframe %r (R5.15: always a keyframe)" % (h["keyframe"],))
        check(h["tick"] == m.body["tick"] == t.body.get("tick"), "ticks: visibility %r, merged %r, TICK %r"
              % (h["tick"], m.body["tick"], t.body.get("tick")))
        check(len(f.att) == h["raw_length"], "attachment %d bytes, raw_length %d" % (len(f.att), h["raw_length"]))
        # the merged part: the plain GET_VOLUME of the same tick, header and values
        check(f.att[:vd["raw_offset"]] == m.att, "%s: the %d bytes before the visibility differ from GET_VOLUME's "
              "merged volume of the same tick (%d bytes)" % (fmt, vd["raw_offset"], len(m.att)))
        mine = dict(h, raw_length=None, volume=dict((k, v) for k, v in d.items() if k != "visibility"))
        theirs = dict(m.body, raw_length=None)
        diff = sorted(k for k in set(mine) | set(theirs) if mine.get(k) != theirs.get(k))
        check(not diff, "%s: the content visibility header differs from the merged one in %r, not only in "
              "raw_length and volume.visibility (R5.15)" % (fmt, diff))
        check(h["raw_length"] == m.body["raw_length"] + vd["raw_length"], "raw_length %r, the merged volume's %r + "
              "the visibility's %r (R5.15)" % (h["raw_length"], m.body["raw_length"], vd["raw_length"]))
        vis = f32_list(f.att[vd["raw_offset"]:])
        check(is_finite_list(vis), "%s: non-finite values in the visibility" % fmt)
        seen[fmt] = (vd, f.att[vd["raw_offset"]:])
        if fmt == "fp32":
            notes.append(_probes_values_checks(d, vis))
    same = [k for k in seen["fp32"][0] if k != "raw_offset"]  # the levels' values are half as long in fp16
    check([seen["fp32"][0].get(k) for k in same] == [seen["fp16"][0].get(k) for k in same]
          and sorted(seen["fp32"][0]) == sorted(seen["fp16"][0]),
          "the visibility is described otherwise in fp32 %r and fp16 %r" % (seen["fp32"][0], seen["fp16"][0]))
    check(seen["fp32"][1] == seen["fp16"][1], "the visibility of the same tick differs between fp32 and fp16 "
          "(R5.15: binary32 whatever the format)")
    z = expect_reply(c.request(GET_VOLUME, {"format": "fp16", "compression": "zstd", "content": "visibility"}),
                     GET_VOLUME)
    _vol_header_checks(z.body, "fp16", "zstd", PROBES_CONFIG["grid"], visibility=True)
    zs = zstd_frame_content_size(z.att)
    check(zs[0] and zs[1] in (None, z.body["raw_length"]), "zstd visibility: content size %r (%s), raw_length %d"
          % (zs[1], zs[2], z.body["raw_length"]))
    dec = zstd_decompress_cli(z.att)
    if dec is not None:
        check(len(dec) == z.body["raw_length"] and dec[z.body["volume"]["visibility"]["raw_offset"]:] ==
              seen["fp16"][1], "zstd fp16 visibility decompresses to other bytes than the uncompressed one")
    # the VOLUME stream carries the merged volume (no "visibility": _vol_header_checks)
    expect_reply(c.request(SUBSCRIBE, {"stream": "volume", "format": "fp32", "compression": "none"}), SUBSCRIBE)
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    v = c.recv_stream(VOLUME, timeout=ctx.tick_timeout)
    _vol_header_checks(v.body, "fp32", "none", PROBES_CONFIG["grid"])
    check(v.body["volume"]["technique"] == "probes", "the stream's volume names technique %r"
          % (v.body["volume"]["technique"],))
    expect_reply(c.request(UNSUBSCRIBE, {"stream": "volume"}), UNSUBSCRIBE)
    notes.append(_probes_lookup_vs_query(ctx, c, 15))
    # another technique: content "visibility" is refused naming content
    expect_reply(c.request(CONFIG, {"technique": "lpv"}), CONFIG)
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    rid = c.send(GET_VOLUME, {"format": "fp32", "content": "visibility"})
    expect_error(c.recv_reply(rid), "BAD_FIELD", rid, "content")
    return "%s; %s; lpv refused" % tuple(notes)


def _probes_values_checks(d, vis):
    """R5.15: each probe's values in range: active 0 or 1 (some on), each
    offset component under half its level's cell, the distance moments
    mean >= 0 and mean square >= mean^2 (up to binary32 rounding), both
    within the 2 cells they are clamped at, the irradiance >= 0 (some > 0).
    Returns a summary."""
    v = d["visibility"]
    I, D, V = v["irradiance_side"], v["distance_side"], v["values_per_probe"]
    eps = 1e-5
    on, lit, moved, worst_off, at = 0, 0, 0, 0.0, 0
    for k, lv in enumerate(d["levels"]):
        s = lv["cell_size"]
        for i in range(lv["cells"]):
            base = (at + i) * V
            pv = vis[base:base + V]
            where = "level %d probe %d" % (k, i)
            check(pv[3] in (0.0, 1.0), "%s: active %r, R5.15 has 1 or 0" % (where, pv[3]))
            on += pv[3] == 1.0
            off = max(abs(x) for x in pv[0:3])
            moved += off > 0.0
            worst_off = max(worst_off, off / s)
            check(off < 0.5 * s, "%s: offset %r, a component not under half the cell %g m (R5.15)"
                  % (where, pv[0:3], s))
            irr = pv[4:4 + 3 * I * I]
            check(min(irr) >= 0.0, "%s: an irradiance texel %g < 0 W/m^2" % (where, min(irr)))
            lit += max(irr) > 0.0
            for t in range(D * D):
                mu, mu2 = pv[4 + 3 * I * I + 2 * t], pv[4 + 3 * I * I + 2 * t + 1]
                check(mu >= 0.0 and mu2 >= mu * mu * (1.0 - eps) - eps * s * s,
                      "%s distance texel %d: mean %r, mean square %r (R5.15: mean >= 0, mean square >= mean^2)"
                      % (where, t, mu, mu2))
                check(mu <= 2.0 * s * (1.0 + eps) and mu2 <= 4.0 * s * s * (1.0 + eps),
                      "%s distance texel %d: mean %r m, mean square %r m^2 beyond the 2 cells (%g m) the distances "
                      "are clamped at (R5.15)" % (where, t, mu, mu2, 2.0 * s))
        at += lv["cells"]
    check(at == v["probes"], "the levels have %d probes, the visibility %d" % (at, v["probes"]))
    check(on > 0, "every probe of a box scene is off")
    check(lit > 0, "no probe's irradiance map holds light in a lit box")
    return "%d probes (%d on, %d lit, %d moved, up to %.3f cells), maps %d^2 and %d^2, bias %g cells" % (
        at, on, lit, moved, worst_off, I, D, v["bias_cells"])


# a closed block in the test box (R5.15's levels case): probes inside it are off or moved out of it
PROBES_BLOCK = ((-0.45, 0.1, -0.45), (0.33, 0.8, 0.3))


@case("R5.15 R4.7", "technique probes with three cascades, a block in the box: R5.15's lookup (level choice, "
      "fallback, blend, probes off or moved) on content visibility agrees with QUERY_IRRADIANCE")
def c_volume_probes_levels(ctx):
    if "probes" not in _iv_techniques(ctx):
        return "HELLO lists no \"probes\" (R4.14): nothing to look up"
    c = ctx.session()
    expect_reply(c.request(SCENE_LOAD, {}, box_scene_glb(block=PROBES_BLOCK), timeout=ctx.tick_timeout), SCENE_LOAD,
                 what="SCENE_LOAD (the test box with a block)")
    expect_reply(c.request(CONFIG, dict(PROBES_CONFIG, cascades=3)), CONFIG)
    expect_reply(c.request(LIGHT_SET, unique_light("probes-levels")), LIGHT_SET)
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    f = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none", "content": "visibility"}),
                     GET_VOLUME)
    _vol_header_checks(f.body, "fp32", "none", PROBES_CONFIG["grid"], visibility=True)
    levels = f.body["volume"]["levels"]
    # (the cascades knob is described as the LPV's, R4.12; lpvd's probes sit in the LPV's cascades, R4.14)
    values = _probes_values_checks(f.body["volume"], f32_list(f.att[f.body["volume"]["visibility"]["raw_offset"]:]))
    return "%d level(s) of %s m%s; %s; %s" % (
        len(levels), "/".join("%.3g" % lv["cell_size"] for lv in levels),
        "" if len(levels) > 1 else " (CONFIG cascades 3 gave one: steps 3 and 4 across levels not exercised)",
        values, _probes_lookup_vs_query(ctx, c, 16, 60, 90, _block_surfaces(PROBES_BLOCK)))


@case("R5.1", "GET_VOLUME fp32/none: sizes match the grid dims; values finite")
def c_volume_fp32(ctx):
    c, cfg, t = ctx.scene_session()
    f = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    cells = _vol_header_checks(f.body, "fp32", "none", SMALL_CONFIG["grid"])
    check(f.body["keyframe"] is True, "GET_VOLUME keyframe %r, expected true" % f.body["keyframe"])
    check(f.body["tick"] == t.body.get("tick"), "volume tick %r, expected %r" % (f.body["tick"], t.body.get("tick")))
    check(len(f.att) == f.body["raw_length"], "attachment %d bytes, raw_length %d" % (len(f.att),
                                                                                    f.body["raw_length"]))
    vals = f32_list(f.att)
    check(is_finite_list(vals), "non-finite values in the volume")
    dc = vals[0::4]
    check(any(x != 0.0 for x in dc), "the volume of a lit box is all zero")
    return "%d cells, %d bytes" % (cells, len(f.att))


@case("R5.1 R4.7", "volume layout (x fastest, r0..r3 g0..g3 b0..b3, Y00 Y1-1 Y10 Y11) agrees with the "
      "server's own irradiance lookup at cell centres")
def c_volume_layout(ctx):
    c, cfg, t = ctx.scene_session(config={"technique": "lpv", "grid": [12, 10, 8], "iterations": 4, "rsm_size": 64,
                                          "normal_bins": False, "far_field": False},  # see SMALL_CONFIG
                                  light={"id": "lay-%d" % os.getpid(), "type": "point", "color": [1.0, 0.6, 0.3],
                                         "intensity": 30.0, "position": [0.55, 0.6, -0.35]})
    v = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    g = v.body.get("grid", {})
    dims, origin, cell = g.get("dims"), g.get("origin"), g.get("cell_size")
    check(dims == [12, 10, 8], "dims %r, expected [12, 10, 8]" % dims)
    vals = f32_list(v.att)
    nx, ny, nz = dims
    rnd = random.Random(11)
    normals = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1),
               (1 / math.sqrt(3), 1 / math.sqrt(3), -1 / math.sqrt(3))]
    probes = []
    # With several cascades the server blends cascade 0 with the next within
    # 3 cells of its border (R5.7): probe only deeper than that.
    m = 3 if len(v.body.get("cascades") or [1]) > 1 else 1
    for _ in range(60):
        i, j, k = rnd.randrange(m, nx - m), rnd.randrange(m, ny - m), rnd.randrange(m, nz - m)
        n = normals[rnd.randrange(len(normals))]
        q = [origin[a] + ((i, j, k)[a] + 0.5) * cell for a in range(3)]
        p = [q[a] - 0.5 * cell * n[a] for a in range(3)]
        probes.append(((i, j, k), n, p))
    att = b"".join(struct.pack("<6f", *(pr[2] + list(pr[1]))) for pr in probes)
    f = expect_reply(c.request(QUERY_IRRADIANCE, {"count": len(probes)}, att), QUERY_IRRADIANCE)
    check(f.body.get("tick") == v.body.get("tick"), "query tick %r != volume tick %r" % (f.body.get("tick"),
                                                                                       v.body.get("tick")))
    got = f32_list(f.att)
    want = []
    for (i, j, k), n, _ in probes:
        base = (i + nx * (j + ny * k)) * 12
        lobe = (SH_LOBE0, -SH_LOBE1 * n[1], -SH_LOBE1 * n[2], -SH_LOBE1 * n[0])  # lobe(-n)
        for ch in range(3):
            cc = vals[base + ch * 4:base + ch * 4 + 4]
            want.append(max(0.0, sum(a * b for a, b in zip(cc, lobe)) / (cell * cell)))
    scale = max(max(want), 1e-30)
    check(max(want) > 0, "all expected irradiances are zero (the light does not reach the probes?)")
    bad = [(idx, w, x) for idx, (w, x) in enumerate(zip(want, got)) if abs(w - x) > 2e-3 * abs(w) + 1e-5 * scale]
    check(not bad, "%d of %d channel values differ, e.g. probe %d channel %d: from the volume %.6g, queried %.6g "
          "(layout or coefficient order differs from SPEC section 5)" % (len(bad), len(want), bad[0][0] // 3,
                                                                         bad[0][0] % 3, bad[0][1], bad[0][2])
          if bad else "")
    return "%d probes x 3 channels agree (max %.4g W/m^2)" % (len(probes), max(want))


@case("R5.1 R5.4", "GET_VOLUME fp16 agrees with fp32 within fp16 precision; no Inf/NaN")
def c_volume_fp16(ctx):
    c, cfg, t = ctx.scene_session()
    a = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    h = expect_reply(c.request(GET_VOLUME, {"format": "fp16", "compression": "none"}), GET_VOLUME)
    _vol_header_checks(h.body, "fp16", "none", SMALL_CONFIG["grid"])
    check(h.body["tick"] == a.body["tick"], "fp16 and fp32 volumes from different ticks")
    check(len(h.att) == h.body["raw_length"], "attachment %d bytes, raw_length %d" % (len(h.att),
                                                                                    h.body["raw_length"]))
    fa, fh = f32_list(a.att), f16_list(h.att)
    check(len(fa) == len(fh), "value counts differ: fp32 %d, fp16 %d" % (len(fa), len(fh)))
    worst = 0.0
    for i, (x, y) in enumerate(zip(fa, fh)):
        if not math.isfinite(y):
            raise Fail("fp16 value %d is %r (R5.4: never Inf or NaN)" % (i, y))
        if abs(x) > 65504:
            check(y == math.copysign(65504.0, x), "value %d: fp32 %g should clamp to +-65504, got %g" % (i, x, y))
            continue
        tol = max(abs(x) * 2.0 ** -11, 2.0 ** -25) * 1.001
        err = abs(x - y)
        if err > tol:
            raise Fail("value %d: fp32 %.9g vs fp16 %.9g (error %.3g > %.3g)" % (i, x, y, err, tol))
        if abs(x) >= 2.0 ** -14:
            worst = max(worst, err / abs(x))
    return "%d values agree (worst relative error %.2g over the normal fp16 range)" % (len(fa), worst)


@case("R5.2", "GET_VOLUME zstd: one zstd frame whose content is raw_length bytes (fp16 and fp32)")
def c_volume_zstd(ctx):
    c, cfg, t = ctx.scene_session()
    notes = []
    for fmt in ("fp32", "fp16"):
        raw = expect_reply(c.request(GET_VOLUME, {"format": fmt, "compression": "none"}), GET_VOLUME)
        z = expect_reply(c.request(GET_VOLUME, {"format": fmt, "compression": "zstd"}), GET_VOLUME)
        _vol_header_checks(z.body, fmt, "zstd", SMALL_CONFIG["grid"])
        check(z.body["raw_length"] == len(raw.att), "%s zstd raw_length %r, uncompressed volume is %d bytes"
              % (fmt, z.body["raw_length"], len(raw.att)))
        ok, size, why = zstd_frame_content_size(z.att)
        check(ok, "%s: %s" % (fmt, why))
        if size is not None:
            check(size == z.body["raw_length"], "%s: zstd frame content size %d != raw_length %d"
                  % (fmt, size, z.body["raw_length"]))
        dec = zstd_decompress_cli(z.att)
        if dec is not None:
            check(dec == raw.att, "%s: decompressed zstd volume differs from the uncompressed one" % fmt)
            notes.append("%s %d->%d B, decoded and equal" % (fmt, len(raw.att), len(z.att)))
        else:
            notes.append("%s %d->%d B (magic/size only)" % (fmt, len(raw.att), len(z.att)))
    return "; ".join(notes)


@case("R5.1", "GET_VOLUME defaults (no format/compression given) are a valid volume")
def c_volume_defaults(ctx):
    c, cfg, t = ctx.scene_session()
    f = expect_reply(c.request(GET_VOLUME, {}), GET_VOLUME)
    fmt, comp = f.body.get("format"), f.body.get("compression")
    check(fmt in ("fp16", "fp32") and comp in ("zstd", "none"), "format/compression %r/%r" % (fmt, comp))
    _vol_header_checks(f.body, fmt, comp, SMALL_CONFIG["grid"])
    if comp == "none":
        check(len(f.att) == f.body["raw_length"], "attachment %d != raw_length" % len(f.att))
    else:
        ok, size, why = zstd_frame_content_size(f.att)
        check(ok, why)
    return "%s/%s" % (fmt, comp)


@case("R5.1", "CONFIG grid change is reflected in the volume dims (non-cubic grid, x fastest size)")
def c_volume_dims(ctx):
    # the LPV's grid (see SMALL_CONFIG: auto, the default since issue 30, places iv's voxels by iv_resolution)
    c, cfg, t = ctx.scene_session(config={"technique": "lpv", "grid": [8, 12, 6], "iterations": 4, "rsm_size": 64})
    f = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    cells = _vol_header_checks(f.body, "fp32", "none", [8, 12, 6])
    check(all(e["dims"] == [8, 12, 6] for e in f.body["cascades"]), "cascade dims %r, expected [8, 12, 6] each"
          % [e["dims"] for e in f.body["cascades"]])
    check(len(f.att) == cells * 48 == 8 * 12 * 6 * 48 * len(f.body["cascades"]),
          "attachment %d bytes, expected %d" % (len(f.att), cells * 48))
    return "8x12x6 x %d cascade(s) = %d cells" % (len(f.body["cascades"]), cells)


@case("R5.16 R4.12", "HELLO lists volume_codecs: the compressions none, zstd, shq and shq's error bounds")
def c_volume_codecs(ctx):
    ctx.session().close()
    codecs = (ctx.hello_reply or {}).get("volume_codecs")
    check(isinstance(codecs, dict), "HELLO reply has no object \"volume_codecs\": %r" % (codecs,))
    check(codecs == SHQ_CODECS, "HELLO volume_codecs %r, R5.16 says %r" % (codecs, SHQ_CODECS))
    return "volume_codecs %r" % (codecs,)


def _shq_get_volume(c, bound, dims=None):
    """GET_VOLUME compression "shq" (bound None: the default), then fp32 and
    "none" of the same tick: the header, the zstd frame and the payload
    checked, every cell within the bound of the exact volume. Returns a
    note."""
    body = {"compression": "shq"}
    if bound is not None:
        body["error_bound"] = bound
    q = expect_reply(c.request(GET_VOLUME, body), GET_VOLUME)
    x = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    _vol_header_checks(q.body, "fp32", "shq", dims)
    want = SHQ_CODECS["error_bound"]["default"] if bound is None else bound
    check(q.body.get("error_bound") == want, "header error_bound %r, asked %r" % (q.body.get("error_bound"), bound))
    check(q.body["keyframe"] is True, "GET_VOLUME shq is not a keyframe")
    check(q.body["tick"] == x.body["tick"] and q.body["revision"] == x.body["revision"],
          "shq of tick %r (revision %r), fp32 of tick %r (revision %r)" % (
              q.body["tick"], q.body["revision"], x.body["tick"], x.body["revision"]))
    check(q.body["raw_length"] == x.body["raw_length"] == len(x.att), "raw_length %r, the fp32 volume's %r (%d bytes)"
          % (q.body["raw_length"], x.body["raw_length"], len(x.att)))
    ok, size, why = zstd_frame_content_size(q.att)
    check(ok, "R5.16 (R5.2): %s" % why)
    payload = zstd_decompress_cli(q.att)
    label = "bound %g%s" % (want, " (the default)" if bound is None else "")
    if payload is None:
        return "%s: %d B (zstd frame only: no zstd tool)" % (label, len(q.att))
    check(size is None or size == len(payload), "zstd frame content size %r, the payload is %d bytes"
          % (size, len(payload)))
    raw, cells = _shq_decode(q.body, payload)  # a keyframe: every cell sent
    worst = _shq_bound_checks(raw, x.att, want, cells, "GET_VOLUME shq %g" % want)
    return "%s: %d B for %d B of fp32, %d cells within %.2f of the bound" % (label, len(q.att), len(x.att), cells,
                                                                              worst)


@case("R5.16 R5.2", "GET_VOLUME compression shq at bounds 0.01, 0.1 and the default: format fp32, error_bound, "
      "every cell within the bound of GET_VOLUME fp32 of the same tick; an iv volume's index as is")
def c_volume_shq(ctx):
    c, cfg, t = ctx.scene_session(light=unique_light("shq-get"))
    notes = [_shq_get_volume(c, b, SMALL_CONFIG["grid"]) for b in (0.01, 0.1, None)]
    if "iv" in _iv_techniques(ctx):  # a volume with an index after its values (R5.12, R5.14): X bytes
        c, cfg, t = ctx.scene_session(config=IV_CONFIG, light=unique_light("shq-iv"))
        notes.append("iv " + _shq_get_volume(c, 0.05))
    return "; ".join(notes)


@case("R5.16 R2.9", "BAD_FIELD for error_bound out of range or not a number, error_bound without shq, fp16 with "
      "shq, shq with content levels (GET_VOLUME and SUBSCRIBE); nothing is subscribed")
def c_volume_shq_refused(ctx):
    octree = "octree" in _iv_techniques(ctx)  # content "levels" is valid there: the refusal is shq's
    config = dict(SMALL_CONFIG, grid=[8, 8, 8], technique="octree") if octree else None
    c, cfg, t = ctx.scene_session(config=config, light=unique_light("shq-bad"))
    bad = [({"compression": "shq", "error_bound": 0.0005}, "error_bound"),
           ({"compression": "shq", "error_bound": 0.5}, "error_bound"),
           ({"compression": "shq", "error_bound": "x"}, "error_bound"),
           ({"compression": "zstd", "error_bound": 0.01}, "error_bound"),
           ({"compression": "shq", "format": "fp16"}, "format")]
    for body, field in bad:
        for req, extra in ((GET_VOLUME, {}), (SUBSCRIBE, {"stream": "volume"})):
            rid = c.send(req, dict(body, **extra))
            expect_error(c.recv_reply(rid), "BAD_FIELD", rid, field)
    if octree:
        expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "zstd", "content": "levels"}),
                     GET_VOLUME, what="content levels of an octree session with zstd")
    rid = c.send(GET_VOLUME, {"compression": "shq", "content": "levels"})
    f = c.recv_reply(rid)
    expect_error(f, "BAD_FIELD", rid)
    check("shq" in f.body["message"] or "compression" in f.body["message"] or "content" in f.body["message"],
          "shq with content levels refused with %r, naming neither compression nor content" % f.body["message"])
    expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK)
    ctx.ping(c)
    check(not [s for s in c.streams if s.type == VOLUME], "a refused SUBSCRIBE subscribed: a VOLUME came")
    return "%d refusals each for GET_VOLUME and SUBSCRIBE, and shq with content levels (%s): %s" % (
        len(bad), "octree" if octree else "lpv", f.body["message"])
