"""conf_volume_checks.py - checks shared by the volume, stream and plan cases: a volume header
(R5.1, R5.6), its "volume" description (R5.9 - R5.15), the tick plan (SPEC section 8),
R5.14's and R5.15's irradiance lookups and R5.16's shq decoding and bound written from the
SPEC, and technique iv's and probes' small CONFIGs."""

import math
import struct

from conf_core import check


def _vol_header_checks(h, fmt, comp, dims=None, visibility=False):
    """A volume header (R5.1, R5.6) and its description (R5.9 - R5.15); with
    visibility False (every reply but GET_VOLUME content "visibility") the
    description must not have R5.15's "visibility", with True it must.
    Returns the cells of all cascades."""
    for k in ("revision", "tick", "format", "compression", "keyframe", "grid", "units", "layout", "sh",
              "raw_length"):
        check(k in h, "volume header has no %r: %r" % (k, h))
    check(h["format"] == fmt, "format %r, expected %r" % (h["format"], fmt))
    check(h["compression"] == comp, "compression %r, expected %r" % (h["compression"], comp))
    want_units = IV_UNITS if _iv_levels(h.get("volume") or {}) else "W/sr"  # R5.14: an iv volume holds radiance
    check(h["units"] == want_units, "units %r, expected %s" % (h["units"], want_units))
    g = h["grid"]
    check(isinstance(g, dict) and isinstance(g.get("dims"), list) and len(g["dims"]) == 3
          and all(isinstance(x, int) and x > 0 for x in g["dims"]), "grid.dims %r" % g)
    check(isinstance(g.get("origin"), list) and len(g["origin"]) == 3, "grid.origin %r" % g.get("origin"))
    check(isinstance(g.get("cell_size"), (int, float)) and g["cell_size"] > 0, "grid.cell_size %r"
          % g.get("cell_size"))
    if dims is not None:
        check(g["dims"] == list(dims), "grid.dims %r, expected the configured %r" % (g["dims"], list(dims)))
    cells = _cascades_checks(h)
    d = _description_checks(h)
    if visibility:
        check("visibility" in d, "GET_VOLUME content \"visibility\": the description has no \"visibility\" (R5.15)")
    else:
        check("visibility" not in d, "volume.visibility %r in a reply that is not GET_VOLUME content \"visibility\" "
              "(R5.15: present only there)" % (d.get("visibility"),))
    _plan_checks(h.get("plan"), "volume header")
    return cells


INDEX_VALUE_SIZE = 4  # R5.12: index values are little-endian u32


def _description_checks(h):
    """R5.9 - R5.12: the header's "volume" description, checked against the
    legacy keys, the cascades and raw_length. Everything it says is read
    from the header, so a technique with other values passes as long as it is
    consistent. Returns the description."""
    d = h.get("volume")
    check(isinstance(d, dict), "volume header has no \"volume\" description object (R5.9): %r" % (d,))
    check(isinstance(d.get("layout_version"), int) and not isinstance(d.get("layout_version"), bool)
          and d["layout_version"] >= 1, "volume.layout_version %r: expected an integer >= 1 (R5.9)"
          % (d.get("layout_version"),))
    check(isinstance(d.get("technique"), str) and d["technique"], "volume.technique %r: expected a name (R5.9)"
          % (d.get("technique"),))
    check(d.get("units") == h.get("units"), "volume.units %r differs from the header's units %r (R5.11)"
          % (d.get("units"), h.get("units")))
    check(isinstance(d.get("far_field"), bool), "volume.far_field %r: expected a boolean (R5.10)"
          % (d.get("far_field"),))
    levels, cs = d.get("levels"), h["cascades"]
    octree, iv = _octree_levels(d), _iv_levels(d)
    if octree:  # R5.13: content "levels", the octree's levels over cascades[0]
        _octree_level_checks(d, cs)
    elif iv:  # R5.14: technique iv's one level of voxels
        _iv_level_checks(d, cs, h)
    else:
        check(isinstance(levels, list) and len(levels) == len(cs), "volume.levels %r: expected %d levels, one "
              "per cascade (R5.10)" % (levels, len(cs)))
    for k, (lv, c) in enumerate(zip(levels, cs) if not (octree or iv) else ()):
        for key in ("dims", "origin", "cell_size", "cells"):
            check(isinstance(lv, dict) and lv.get(key) == c.get(key), "volume.levels[%d].%s %r differs from "
                  "cascades[%d].%s %r (R5.10)" % (k, key, lv.get(key) if isinstance(lv, dict) else lv, k, key,
                                                  c.get(key)))
        want = "far_field" if d["far_field"] and k > 0 else "cascade"
        check(lv.get("role") == want, "volume.levels[%d].role %r with far_field %r, expected %r (R5.10)"
              % (k, lv.get("role"), d["far_field"], want))
    vpc, vpl = d.get("values_per_cell"), d.get("volumes_per_level")
    for key, v in (("values_per_cell", vpc), ("volumes_per_level", vpl)):
        check(isinstance(v, int) and not isinstance(v, bool) and v >= 1, "volume.%s %r: expected an integer "
              ">= 1 (R5.11)" % (key, v))
    vals = d.get("values")
    check(isinstance(vals, list) and len(vals) == vpc, "volume.values has %s names, values_per_cell is %d (R5.11)"
          % (len(vals) if isinstance(vals, list) else repr(vals), vpc))
    check(all(isinstance(v, str) and v for v in vals) and len(set(vals)) == len(vals),
          "volume.values %r: expected distinct non-empty names (R5.11)" % (vals,))
    size = 2 if h["format"] == "fp16" else 4
    cells = sum(c["cells"] for c in (levels if octree else cs))
    values_bytes = cells * vpl * vpc * size
    index, index_bytes = d.get("index", None), 0
    check("index" in d, "volume has no \"index\" key (null when there is none, R5.12)")
    if index is not None:
        check(isinstance(index, dict), "volume.index %r: expected null or an object (R5.12)" % (index,))
        n = 1
        for x in index.get("dims", []):
            n *= x
        index_bytes = n * index.get("values_per_cell", 0) * INDEX_VALUE_SIZE
        check(index.get("raw_offset") == values_bytes, "volume.index.raw_offset %r, the levels' values end at %d "
              "(R5.12)" % (index.get("raw_offset"), values_bytes))
        check(index.get("raw_length") == index_bytes, "volume.index.raw_length %r, expected %d (R5.12)"
              % (index.get("raw_length"), index_bytes))
    vis_bytes = _visibility_checks(d, cells, values_bytes) if "visibility" in d else 0
    check(h["raw_length"] == values_bytes + index_bytes + vis_bytes, "raw_length %r, expected cells(%d, all levels) "
          "x %d volume(s) x %d values x %d bytes%s%s = %d (R5.6, R5.11, R5.15)" % (
              h["raw_length"], cells, vpl, vpc, size, " + index %d" % index_bytes if index_bytes else "",
              " + visibility %d" % vis_bytes if vis_bytes else "", values_bytes + index_bytes + vis_bytes))
    return d


PROBES_VALUE_TYPE = "f32"  # R5.15: the visibility is binary32 whatever the format


def _is_int(v):
    return isinstance(v, int) and not isinstance(v, bool)


def _visibility_checks(d, cells, values_bytes):
    """R5.15: the description's "visibility": P = the levels' cells, I in
    1..16, D in 1..32, V = 4 + 3 I^2 + 2 D^2, value_type "f32", bias_cells a
    number >= 0, raw_offset = the levels' values' bytes, raw_length = P x V x
    4; over the merged levels (role "cascade", far_field false, no index).
    Returns raw_length."""
    v = d["visibility"]
    check(isinstance(v, dict), "volume.visibility %r: expected an object (R5.15)" % (v,))
    for key in ("probes", "irradiance_side", "distance_side", "values_per_probe", "value_type", "bias_cells",
                "raw_offset", "raw_length"):
        check(key in v, "volume.visibility has no %r: %r (R5.15)" % (key, v))
    check(_is_int(v["probes"]) and v["probes"] == cells, "volume.visibility.probes %r, the levels have %d cells (a "
          "probe a cell, R5.15)" % (v["probes"], cells))
    I, D = v["irradiance_side"], v["distance_side"]
    check(_is_int(I) and 1 <= I <= 16, "volume.visibility.irradiance_side %r: expected an integer in 1..16 (R5.15)"
          % (I,))
    check(_is_int(D) and 1 <= D <= 32, "volume.visibility.distance_side %r: expected an integer in 1..32 (R5.15)"
          % (D,))
    V = 4 + 3 * I * I + 2 * D * D
    check(_is_int(v["values_per_probe"]) and v["values_per_probe"] == V, "volume.visibility.values_per_probe %r, "
          "expected 4 + 3 x %d^2 + 2 x %d^2 = %d (R5.15)" % (v["values_per_probe"], I, D, V))
    check(v["value_type"] == PROBES_VALUE_TYPE, "volume.visibility.value_type %r, expected %r whatever the format "
          "(R5.15)" % (v["value_type"], PROBES_VALUE_TYPE))
    b = v["bias_cells"]
    check(isinstance(b, (int, float)) and not isinstance(b, bool) and math.isfinite(b) and b >= 0,
          "volume.visibility.bias_cells %r: expected a number >= 0 (R5.15)" % (b,))
    check(_is_int(v["raw_offset"]) and v["raw_offset"] == values_bytes, "volume.visibility.raw_offset %r, the "
          "levels' values end at %d (R5.15)" % (v["raw_offset"], values_bytes))
    check(_is_int(v["raw_length"]) and v["raw_length"] == cells * V * 4, "volume.visibility.raw_length %r, expected "
          "%d probes x %d values x 4 = %d (R5.15)" % (v["raw_length"], cells, V, cells * V * 4))
    check(d.get("index") is None and d.get("far_field") is False
          and all(lv.get("role") == "cascade" for lv in d["levels"]),
          "volume.visibility with index %r, far_field %r, roles %r: R5.15's volume is the merged one (role "
          "\"cascade\", far_field false, no index)" % (d.get("index"), d.get("far_field"),
                                                        [lv.get("role") for lv in d["levels"]]))
    return v["raw_length"]


OCTREE_LEVEL_ROLE = "octree_level"  # R5.13: the role of an octree's levels


def _octree_levels(d):
    """Whether a description's levels are an octree's (R5.13)."""
    levels = d.get("levels")
    return isinstance(levels, list) and bool(levels) and isinstance(levels[0], dict) \
        and levels[0].get("role") == OCTREE_LEVEL_ROLE


def _octree_level_checks(d, cs):
    """R5.13: the cascades are level 0 alone; l = log2(n) + 1 levels, level i
    at level 0's origin with dims n >> i and cell size 2^i x level 0's; far
    field false; an index over level 0, one u32 per cell."""
    levels = d["levels"]
    check(len(cs) == 1, "octree levels with %d cascades; the legacy keys describe level 0 alone (R5.13)" % len(cs))
    n = cs[0]["dims"][0]
    check(cs[0]["dims"] == [n, n, n] and n & (n - 1) == 0, "octree levels over level 0 of dims %r: not a cube of a "
          "power of two (R5.13)" % (cs[0]["dims"],))
    check(len(levels) == n.bit_length(), "%d octree levels over %d^3 cells, expected log2(n) + 1 = %d (R5.13)"
          % (len(levels), n, n.bit_length()))
    check(d.get("far_field") is False, "volume.far_field %r with octree levels, expected false (R5.13)"
          % (d.get("far_field"),))
    for i, lv in enumerate(levels):
        m, cell = n >> i, cs[0]["cell_size"] * (1 << i)
        check(isinstance(lv, dict) and lv.get("role") == OCTREE_LEVEL_ROLE and lv.get("dims") == [m, m, m]
              and lv.get("cells") == m ** 3 and lv.get("origin") == cs[0]["origin"]
              and abs(lv.get("cell_size", 0) - cell) <= 1e-9 * cell,
              "volume.levels[%d] %r: expected role %r, dims %r, cells %d, origin %r (level 0's), cell_size %g "
              "(R5.13)" % (i, lv, OCTREE_LEVEL_ROLE, [m, m, m], m ** 3, cs[0]["origin"], cell))
    ix = d.get("index")
    check(isinstance(ix, dict) and ix.get("level") == 0 and ix.get("dims") == [n, n, n]
          and ix.get("values_per_cell") == 1 and ix.get("value_type") == "u32",
          "volume.index %r: octree levels need the index over level 0 (level 0, dims %r, values_per_cell 1, u32; "
          "R5.13)" % (ix, [n, n, n]))


IV_VOXELS_ROLE = "iv_voxels"  # R5.14: the role of technique iv's one level
IV_UNITS = "W/(m^2 sr)"  # R5.14: its values are radiance
SH_NAMES = ["%s.%s" % (ch, y) for ch in "rgb" for y in ("Y00", "Y1-1", "Y10", "Y11")]


def _iv_levels(d):
    """Whether a description's levels are technique iv's voxels (R5.14)."""
    levels = d.get("levels")
    return isinstance(levels, list) and bool(levels) and isinstance(levels[0], dict) \
        and levels[0].get("role") == IV_VOXELS_ROLE


def _iv_level_checks(d, cs, h):
    """R5.14: one cascade and one "iv_voxels" level equal to it, far_field
    false, the 12 SH values in one volume, units W/(m^2 sr) (header too), the
    index over level 0 with level 0's dims and one u32 per voxel, and
    iv_neighbours an integer in 1..8."""
    levels = d["levels"]
    check(len(cs) == 1 and len(levels) == 1, "%d levels over %d cascades, R5.14 has one %r level over one cascade"
          % (len(levels), len(cs), IV_VOXELS_ROLE))
    for key in ("dims", "origin", "cell_size", "cells"):
        check(levels[0].get(key) == cs[0].get(key), "volume.levels[0].%s %r differs from cascades[0].%s %r (R5.14)"
              % (key, levels[0].get(key), key, cs[0].get(key)))
    check(d.get("far_field") is False, "volume.far_field %r with %r, expected false (R5.14)"
          % (d.get("far_field"), IV_VOXELS_ROLE))
    check(d.get("volumes_per_level") == 1 and d.get("values") == SH_NAMES, "volume values %r x %r volumes, R5.14 "
          "has the 12 SH values %r in one volume" % (d.get("values"), d.get("volumes_per_level"), SH_NAMES))
    check(d.get("units") == IV_UNITS and h.get("units") == IV_UNITS, "units %r (header %r), R5.14 says %r"
          % (d.get("units"), h.get("units"), IV_UNITS))
    ix = d.get("index")
    check(isinstance(ix, dict) and ix.get("level") == 0 and ix.get("dims") == cs[0]["dims"]
          and ix.get("values_per_cell") == 1 and ix.get("value_type") == "u32",
          "volume.index %r: R5.14 has the index over level 0 (level 0, dims %r, values_per_cell 1, u32)"
          % (ix, cs[0]["dims"]))
    nb = d.get("iv_neighbours")
    check(isinstance(nb, int) and not isinstance(nb, bool) and 1 <= nb <= 8,
          "volume.iv_neighbours %r: expected an integer in 1..8 (R5.14)" % (nb,))


SH_LOBE0 = math.sqrt(math.pi) / 2.0
SH_LOBE1 = math.sqrt(math.pi / 3.0)


_F32 = struct.Struct("<f")


def _f32(x):
    """x rounded to binary32 (R5.14 computes in binary32)."""
    try:
        return _F32.unpack(_F32.pack(x))[0]
    except OverflowError:
        return math.copysign(float("inf"), x)


def _iv_lookup(d, vals, held, p, n):
    """R5.14's lookup written from the SPEC's seven steps: E (r, g, b) at p
    with normal n from the voxels (vals: 12 floats per voxel, x fastest; held:
    the index) of description d's one level."""
    lv = d["levels"][0]
    dims, o, s, N = lv["dims"], [_f32(v) for v in lv["origin"]], _f32(lv["cell_size"]), d["iv_neighbours"]
    f32 = _f32
    p, n = [f32(v) for v in p], [f32(v) for v in n]
    # 1
    if not all(math.isfinite(v) for v in p + n):
        return [0.0, 0.0, 0.0]
    ln = f32(math.sqrt(f32(f32(f32(n[0] * n[0]) + f32(n[1] * n[1])) + f32(n[2] * n[2]))))
    if not (math.isfinite(ln) and ln > f32(1e-8)):
        return [0.0, 0.0, 0.0]
    nh = [f32(v / ln) for v in n]
    b, f = [0] * 3, [0.0] * 3
    for a in range(3):
        # 2
        q = f32(p[a] + f32(f32(0.5 * s) * nh[a]))
        u = f32(f32(f32(q - o[a]) / s) - 0.5)
        if not (-1.0 <= u < dims[a]):
            return [0.0, 0.0, 0.0]
        b[a] = math.floor(u)
        f[a] = f32(u - b[a])
    # 3
    corners = []
    for c in range(8):
        bits = [(c >> a) & 1 for a in range(3)]
        t, dd = 1.0, 0.0
        for a in range(3):
            t = f32(t * (f[a] if bits[a] else f32(1.0 - f[a])))
            e = f32(f[a] - bits[a])
            dd = f32(dd + f32(e * e))
        corners.append((dd, c, [b[a] + bits[a] for a in range(3)], t))
    # 4
    corners.sort(key=lambda e: (e[0], e[1]))
    total, acc = 0.0, [0.0] * 12
    for _, _, v, t in corners[:N]:
        if not all(0 <= v[a] < dims[a] for a in range(3)):
            continue
        # 5
        dv = [f32(f32(o[a] + f32(f32(v[a] + 0.5) * s)) - p[a]) for a in range(3)]
        dl = f32(math.sqrt(f32(f32(f32(dv[0] * dv[0]) + f32(dv[1] * dv[1])) + f32(dv[2] * dv[2]))))
        cos = 0.0
        if dl > 0.0:
            cs = [f32(nh[a] * f32(dv[a] / dl)) for a in range(3)]
            cos = f32(f32(cs[0] + cs[1]) + cs[2])
        wc = f32(t * max(0.0, cos))
        i = v[0] + dims[0] * (v[1] + dims[1] * v[2])
        if held[i]:
            wc = f32(wc / 64.0)
        if not wc > 0.0:
            continue
        total += wc
        for k in range(12):
            acc[k] += wc * vals[12 * i + k]
    if not total > 0.0:
        return [0.0, 0.0, 0.0]
    # 6
    lobe = [f32(SH_LOBE0), f32(f32(SH_LOBE1) * -nh[1]), f32(f32(SH_LOBE1) * -nh[2]), f32(f32(SH_LOBE1) * -nh[0])]
    e3 = []
    for ch in range(3):
        L = [f32(acc[4 * ch + k] / total) for k in range(4)]
        e3.append(f32(f32(f32(f32(L[0] * lobe[0]) + f32(L[1] * lobe[1])) + f32(L[2] * lobe[2])) + f32(L[3] * lobe[3])))
    # 7. made light as a whole colour: luminance y <= 0 gives 0; else y is
    # kept and, where the most negative channel m < 0, the chroma scales
    # by y / (y - 2 m)
    y = f32(f32(f32(e3[0] * f32(0.2126)) + f32(e3[1] * f32(0.7152))) + f32(e3[2] * f32(0.0722)))
    if not y > 0.0:
        return [0.0, 0.0, 0.0]
    m = min(e3)
    if m >= 0.0:
        return list(e3)
    s = f32(y / f32(y - f32(2.0 * m)))
    return list(f32(y + f32(f32(c - y) * s)) for c in e3)


def _cascades_checks(h):
    """R5.6: "cascades" present, 1..4 entries, each consistent, cascade 0 ==
    grid. Returns the cells of all cascades."""
    cs = h.get("cascades")
    check(isinstance(cs, list) and 1 <= len(cs) <= 4, "volume header cascades %r: expected 1 to 4 entries" % (cs,))
    total = 0
    for k, e in enumerate(cs):
        check(isinstance(e, dict), "cascades[%d] %r is not an object" % (k, e))
        d = e.get("dims")
        check(isinstance(d, list) and len(d) == 3 and all(isinstance(x, int) and x > 0 for x in d),
              "cascades[%d].dims %r" % (k, d))
        check(isinstance(e.get("origin"), list) and len(e["origin"]) == 3
              and all(isinstance(x, (int, float)) for x in e["origin"]), "cascades[%d].origin %r" % (k, e.get("origin")))
        check(isinstance(e.get("cell_size"), (int, float)) and e["cell_size"] > 0,
              "cascades[%d].cell_size %r" % (k, e.get("cell_size")))
        n = d[0] * d[1] * d[2]
        check(e.get("cells") == n, "cascades[%d].cells %r, its dims give %d" % (k, e.get("cells"), n))
        if k > 0:
            check(e["cell_size"] > cs[k - 1]["cell_size"], "cascades[%d].cell_size %r is not coarser than "
                  "cascades[%d]'s %r (finest first)" % (k, e["cell_size"], k - 1, cs[k - 1]["cell_size"]))
        total += n
    g = h["grid"]
    check(cs[0]["dims"] == g["dims"], "cascades[0].dims %r != grid.dims %r" % (cs[0]["dims"], g["dims"]))
    check(abs(cs[0]["cell_size"] - g["cell_size"]) <= 1e-9 * g["cell_size"]
          and all(abs(a - b) <= 1e-9 * max(1.0, abs(b)) for a, b in zip(cs[0]["origin"], g["origin"])),
          "cascades[0] %r differs from grid %r" % (cs[0], g))
    return total


PLAN_PASSES = ("rsm", "emissive", "inject", "gbuffer", "gv", "propagate", "bounce", "glossy", "media")


def _plan_checks(plan, where, cascades=None):
    """SPEC section 8: the plan object names every pass with run and a reason."""
    check(isinstance(plan, dict), "%s has no plan object: %r" % (where, plan))
    check(isinstance(plan.get("cascades"), int) and not isinstance(plan.get("cascades"), bool),
          "%s plan.cascades %r" % (where, plan.get("cascades")))
    check(isinstance(plan.get("cascades_reason"), str), "%s plan.cascades_reason %r"
          % (where, plan.get("cascades_reason")))
    check(isinstance(plan.get("recompute"), bool), "%s plan.recompute %r" % (where, plan.get("recompute")))
    check(isinstance(plan.get("recompute_reason"), str), "%s plan.recompute_reason %r"
          % (where, plan.get("recompute_reason")))
    passes = plan.get("passes")
    check(isinstance(passes, list), "%s plan.passes %r" % (where, passes))
    names = [p.get("name") if isinstance(p, dict) else None for p in passes]
    check(tuple(names[:len(PLAN_PASSES)]) == PLAN_PASSES, "%s plan passes %r, expected %r first (R8.1)"
          % (where, names, list(PLAN_PASSES)))
    for p in passes:
        check(isinstance(p.get("run"), bool) and isinstance(p.get("reason"), str),
              "%s plan pass %r: expected a boolean run and a reason string" % (where, p))
    if cascades is not None:
        check(plan["cascades"] == cascades, "%s plan.cascades %r, the volume has %d cascades (R8.2)"
              % (where, plan["cascades"], cascades))


# technique iv kept small for llvmpipe: ~12 voxels along the box, 16 rays, 2 bounces
IV_CONFIG = {"technique": "iv", "iv_resolution": 12, "iv_rays": 16, "iv_bounces": 2}


def _iv_techniques(ctx):
    """The techniques HELLO lists (a fresh session's)."""
    ctx.session().close()
    return (ctx.hello_reply or {}).get("techniques") or []


# technique probes kept small for llvmpipe: 8 probes a side (R5.15)
PROBES_CONFIG = {"technique": "probes", "grid": [8, 8, 8]}
PROBES_UNSEEN = 1e-3  # R5.15 step 3


def _probes_oct(w):
    """R5.15: the octahedral encoding of direction w."""
    l1 = abs(w[0]) + abs(w[1]) + abs(w[2])
    u = [w[0] / l1, w[1] / l1] if l1 > 0 else [0.0, 0.0]
    if w[2] < 0:
        sx = 1.0 if u[0] >= 0 else -1.0
        sy = 1.0 if u[1] >= 0 else -1.0
        u = [(1.0 - abs(u[1])) * sx, (1.0 - abs(u[0])) * sy]
    return u


def _probes_read(vals, at, side, width, w):
    """R5.15: a side x side map of `width` values a texel, starting at
    vals[at], read toward w bilinearly: the `width` values."""
    u = _probes_oct(w)
    b, b1, f = [0, 0], [0, 0], [0.0, 0.0]
    for a in range(2):
        s = min(max((u[a] * 0.5 + 0.5) * side - 0.5, 0.0), side - 1.0)
        b[a] = min(math.floor(s), max(side - 2, 0))
        f[a] = s - b[a]
        b1[a] = min(b[a] + 1, side - 1)
    out = [0.0] * width
    for (col, row), wt in (((b[0], b[1]), (1 - f[0]) * (1 - f[1])), ((b1[0], b[1]), f[0] * (1 - f[1])),
                           ((b[0], b1[1]), (1 - f[0]) * f[1]), ((b1[0], b1[1]), f[0] * f[1])):
        t = at + width * (row * side + col)
        for i in range(width):
            out[i] += wt * vals[t + i]
    return out


def _probes_lookup(d, vis, p, n, stats=None):
    """R5.15's lookup written from the SPEC's four steps: E (r, g, b) at p with
    normal n from description d's levels and vis, the visibility's P x V
    floats. In double precision (binary32 or better) from p and n as sent
    (binary32). stats, a dict, counts what the lookup went through: "crushed"
    probes (w < 0.2), "chebyshev" (delta > mu), "fallback" (step 3 moved to a
    coarser level), "blend" (step 4 blended two levels)."""
    v = d["visibility"]
    I, D, V, bias = v["irradiance_side"], v["distance_side"], v["values_per_probe"], v["bias_cells"]
    levels = d["levels"]
    K = len(levels)
    if not all(math.isfinite(x) for x in list(p) + list(n)):
        return [0.0, 0.0, 0.0]
    ln = math.sqrt(sum(x * x for x in n))
    if not 1e-8 < ln < 1e18:
        return [0.0, 0.0, 0.0]
    nh = [x / ln for x in n]
    first, at = [], 0
    for lv in levels:
        first.append(at)
        at += lv["cells"]
    stats = stats if stats is not None else {}

    def inside(k, x):
        lv = levels[k]
        u = [(x[a] - lv["origin"][a]) / lv["cell_size"] for a in range(3)]
        return min(min(u[a], lv["dims"][a] - u[a]) for a in range(3))

    def level(k):  # step 2: (E(k), h(k))
        lv = levels[k]
        o, s, dims = lv["origin"], lv["cell_size"], lv["dims"]
        x = [p[a] + bias * s * nh[a] for a in range(3)]
        q = [min(max((x[a] - o[a]) / s - 0.5, 0.0), dims[a] - 1.0) for a in range(3)]
        c0 = [min(math.floor(q[a]), max(dims[a] - 2, 0)) for a in range(3)]
        f = [q[a] - c0[a] for a in range(3)]
        h, W, S = 0.0, 0.0, [0.0, 0.0, 0.0]
        for j in range(8):
            e = [j & 1, (j >> 1) & 1, (j >> 2) & 1]
            c = [min(c0[a] + e[a], dims[a] - 1) for a in range(3)]
            base = (first[k] + c[0] + dims[0] * (c[1] + dims[1] * c[2])) * V
            if vis[base + 3] == 0:
                continue
            m = [o[a] + (c[a] + 0.5) * s + vis[base + a] for a in range(3)]
            t = 1.0
            for a in range(3):
                t *= f[a] if e[a] else 1.0 - f[a]
            r = [m[a] - p[a] for a in range(3)]
            rl = math.sqrt(sum(y * y for y in r))
            phi = (sum(r[a] / rl * nh[a] for a in range(3)) + 1.0) / 2.0 if rl > 0 else 1.0
            w = phi * phi + 0.2
            vv = [x[a] - m[a] for a in range(3)]
            delta = math.sqrt(sum(y * y for y in vv))
            mu, mu2 = _probes_read(vis, base + 4 + 3 * I * I, D, 2, [y / delta for y in vv] if delta > 0 else nh)
            if delta > mu:
                stats["chebyshev"] = stats.get("chebyshev", 0) + 1
                var = max(mu2 - mu * mu, 1e-4 * s * s)
                w *= (var / (var + (delta - mu) ** 2)) ** 3
            if w < 0.2:
                stats["crushed"] = stats.get("crushed", 0) + 1
                w = w ** 3 / 0.04
            h += w * t
            w2 = max(w, 1e-6) * t
            irr = _probes_read(vis, base + 4, I, 3, nh)
            for i in range(3):
                S[i] += w2 * irr[i]
            W += w2
        return ([S[i] / W for i in range(3)] if W > 0 else [0.0, 0.0, 0.0]), h

    k = next((i for i in range(K - 1) if inside(i, p) >= 0.5), K - 1)  # step 1
    E, h = level(k)
    while h < PROBES_UNSEEN and k + 1 < K:  # step 3
        stats["fallback"] = stats.get("fallback", 0) + 1
        k += 1
        E, h = level(k)
    om = min(max((inside(k, p) - 0.5) / 2.0, 0.0), 1.0)  # step 4
    if om < 1 and k + 1 < K:
        E1, h1 = level(k + 1)
        if h1 >= PROBES_UNSEEN:
            stats["blend"] = stats.get("blend", 0) + 1
            E = [E1[i] + (E[i] - E1[i]) * om for i in range(3)]
    return E


# R5.16: compression "shq", written from the SPEC (protocol/volume_shq.c is the server's)
SHQ_CODECS = {"compression": ["none", "zstd", "shq"], "error_bound": {"min": 0.001, "max": 0.25, "default": 0.01}}
SHQ_VALUE_LIMIT = _f32(1e30)  # exact values beyond it are clamped (binary32 1e30), NaN is 0, before the bound
SHQ_TINY = 1e-30        # a cell of smaller magnitude is held as zero


def _shq_steps(b, x):
    """round(b x 2^-x), half to even, of a binary32 b, in exact integers
    (R5.16's mode 1: the base's value in the new steps)."""
    n, d = b.as_integer_ratio()  # d a power of two
    num, den = (n << -x, d) if x <= 0 else (n, d << x)
    q, r = divmod(num, den)  # q = floor
    return q + 1 if 2 * r > den or (2 * r == den and q % 2) else q


def _shq_predicted(prev_q, prev_x, x):
    """R5.16's prediction of a predicted keyframe's mantissa: the previous
    cell's q scaled from 2^prev_x to 2^x and rounded half to even, in exact
    integers; 0 where either exponent is -128 or they differ by more than 15."""
    if prev_x == -128 or x == -128 or abs(prev_x - x) > 15:
        return 0
    if prev_x >= x:
        return prev_q << (prev_x - x)
    den = 1 << (x - prev_x)
    q, r = divmod(prev_q, den)  # q = floor
    return q + 1 if 2 * r > den or (2 * r == den and q % 2) else q


def _shq_decode(h, payload, base=None):
    """R5.16's payload (the zstd frame's content) checked against header h
    and decoded: (the raw fp32 volume of raw_length bytes, S the cells
    sent). A delta's cells not flagged keep base's bytes (the volume rebuilt
    for the acknowledged tick) and its bytes after the values are XOR'd with
    the base's; a delta's cell of mode 1 sends the change from the base's
    cell in its steps; a delta with blocks (flag bit 2) first moves the
    base's cells by them (_shq_blocks)."""
    raw_length = h["raw_length"]
    ix = (h.get("volume") or {}).get("index")
    values = ix["raw_offset"] if ix else raw_length
    check(values % 48 == 0, "R5.16: %d bytes of values are not whole cells of 12 fp32 values" % values)
    C, X = values // 48, raw_length - values
    check(len(payload) >= 32 and payload[:4] == b"SHQ1", "R5.16: the payload (%d bytes) starts %r, not \"SHQ1\""
          % (len(payload), bytes(payload[:4])))
    flags, c, s, x = struct.unpack_from("<IQQQ", payload, 4)
    key = flags & 1 == 1
    predicted = flags == 3
    check(flags in (0, 1, 3, 4), "R5.16: payload flags 0x%x (bit 0 keyframe, bit 1 predicted only with it, bit 2 "
          "blocks only without it)" % flags)
    check(key == h["keyframe"], "R5.16: payload flags say keyframe %r, the header %r" % (key, h["keyframe"]))
    check(c == C and x == X, "R5.16: payload counts C %d, X %d; the header's volume has %d cells and %d bytes after "
          "them" % (c, x, C, X))
    check(s <= C and (not key or s == C), "R5.16: %d cells sent of %d in a %s" % (s, C, "keyframe" if key else
                                                                                  "delta"))
    B = 0
    if flags == 4:
        check(base is not None and len(base) == raw_length, "a delta without the acknowledged base of %d bytes"
              % raw_length)
        B, moved = _shq_blocks(payload, C, base[:values])
        base = moved + bytes(base[values:])
    map_len = 0 if key else (C + 7) // 8
    per = 25 if key else 26  # exponent, a delta's mode, 12 two-byte mantissas
    check(len(payload) == 32 + B + map_len + per * s + X, "R5.16: payload of %d bytes, 32 + %d + %d + %d x %d + %d "
          "= %d expected" % (len(payload), B, map_len, per, s, X, 32 + B + map_len + per * s + X))
    if key:
        sent = range(C)
    else:
        check(base is not None and len(base) == raw_length, "a delta without the acknowledged base of %d bytes"
              % raw_length)
        sent = [i for i in range(C) if payload[32 + B + i // 8] >> (i % 8) & 1]
        past = [b for b in range(C, 8 * map_len) if payload[32 + B + b // 8] >> (b % 8) & 1]
        check(len(sent) == s and not past, "R5.16: the bit map flags %d cells (%d past C), S is %d"
              % (len(sent), len(past), s))
    at = 32 + B + map_len
    modes = [0] * s if key else payload[at + s:at + 2 * s]
    lo = at + (1 if key else 2) * s
    hi = lo + 12 * s
    out = bytearray(values) if key else bytearray(base[:values])
    prev_q, prev_x = [0] * 12, -128
    for j, i in enumerate(sent):
        x = struct.unpack_from("<b", payload, at + j)[0]
        check(modes[j] in (0, 1) and not (modes[j] == 1 and x == -128), "R5.16: sent cell %d (cell %d) has mode %d "
              "with exponent %d" % (j, i, modes[j], x))
        b = struct.unpack_from("<12f", base, 48 * i) if modes[j] == 1 else None
        cell = []
        for k in range(12):
            z = payload[lo + k * s + j] + 256 * payload[hi + k * s + j]
            q = z // 2 if z % 2 == 0 else -(z + 1) // 2
            if b is not None:
                q += _shq_steps(b[k], x)
            if predicted:  # the change from the previous cell's prediction, modulo 2^16
                q = (q + _shq_predicted(prev_q[k], prev_x, x) + 32768) % 65536 - 32768
                prev_q[k] = q
            cell.append(0.0 if x == -128 else math.ldexp(q, x))
            check(x == -128 or (abs(q) < 2 ** 53 and abs(cell[-1]) < 2.0 ** 128
                                and struct.unpack("<f", struct.pack("<f", cell[-1]))[0] == cell[-1]),
                  "R5.16: cell %d's value %d is %d x 2^%d (mode %d), not exact in binary32" % (i, k, q, x, modes[j]))
        struct.pack_into("<12f", out, 48 * i, *cell)
        prev_x = x
    tail = bytes(payload[hi + 12 * s:])
    if not key:
        tail = bytes(a ^ b for a, b in zip(tail, base[values:]))
    return bytes(out) + tail, s


def _f32_sum(a, d, x):
    """The binary32 value nearest a + d 2^x (a a binary32 value, d and x
    integers), ties to even, +-inf past the largest: the exact sum as an
    integer times a power of two, rounded to 24 significant bits by hand."""
    num, den = a.as_integer_ratio()  # den a power of two
    e = min(-(den.bit_length() - 1), x)
    n = (num << (-(den.bit_length() - 1) - e)) + (d << (x - e))  # the sum is n 2^e, exactly
    if n == 0:
        return 0.0
    sign, n = (-1.0 if n < 0 else 1.0), abs(n)
    ulp = max(n.bit_length() - 1 + e - 23, -149)  # 24 significant bits, subnormals below 2^-126
    if ulp > e:
        shift = ulp - e
        q, r = n >> shift, n & ((1 << shift) - 1)
        if 2 * r > (1 << shift) or (2 * r == (1 << shift) and q & 1):
            q += 1
    else:
        q = n << (e - ulp)
    if q.bit_length() + ulp > 128:  # q 2^ulp >= 2^128: past the largest binary32
        return sign * float("inf")
    return sign * math.ldexp(q, ulp)


def _shq_blocks(payload, C, values):
    """A delta's blocks (R5.16 bit 2) at payload[32:], checked: (B, their
    bytes; values, the base's values, moved: to each value of each cell of a
    block that is not all zeros, d x 2^x, the sum rounded to binary32)."""
    check(len(payload) >= 40, "R5.16: the blocks' counts are cut off")
    R, edge = struct.unpack_from("<II", payload, 32)
    check(1 <= R <= 16 and 1 <= edge <= 64, "R5.16: %d regions of blocks of edge %d" % (R, edge))
    check(len(payload) >= 40 + 20 * R, "R5.16: the blocks' regions are cut off")
    regions, end, T = [], 0, 0
    for r in range(R):
        f, nx, ny, nz = struct.unpack_from("<QIII", payload, 40 + 20 * r)
        check(nx >= 1 and ny >= 1 and nz >= 1 and f >= end and f + nx * ny * nz <= C,
              "R5.16: region %d (first %d, %d x %d x %d) is not a box of the %d cells after the one before"
              % (r, f, nx, ny, nz, C))
        end = f + nx * ny * nz
        regions.append((f, nx, ny, nz, T))
        T += -(-nx // edge) * -(-ny // edge) * -(-nz // edge)
    at = 40 + 20 * R
    check(len(payload) >= at + 25 * T, "R5.16: the %d blocks are cut off" % T)
    out = bytearray(values)
    for f, nx, ny, nz, t0 in regions:
        bx, by = -(-nx // edge), -(-ny // edge)
        for i in range(nx * ny * nz):
            xc, yc, zc = i % nx, i // nx % ny, i // (nx * ny)
            t = t0 + xc // edge + bx * (yc // edge + by * (zc // edge))
            x = struct.unpack_from("<b", payload, at + t)[0]
            check(x == -128 or x <= 100, "R5.16: block %d has exponent %d" % (t, x))
            cell = struct.unpack_from("<12f", out, 48 * (f + i))
            if x == -128 or all(v == 0 for v in cell):
                continue
            moved = []
            for k in range(12):
                z = payload[at + T + k * T + t] + 256 * payload[at + 13 * T + k * T + t]
                d = z // 2 if z % 2 == 0 else -(z + 1) // 2
                check(math.isfinite(cell[k]), "R5.16: a block moves cell %d's value %d, %r" % (f + i, k, cell[k]))
                moved.append(_f32_sum(cell[k], d, x))
                check(math.isfinite(moved[-1]), "R5.16: block %d moves cell %d's value %d past binary32"
                      % (t, f + i, k))
            struct.pack_into("<12f", out, 48 * (f + i), *moved)
    return 8 + 20 * R + 25 * T, bytes(out)


def _shq_magnitude(c):
    """R5.16's M of 12 values: max over channels of L0 |c0| + L1 |(c1, c2, c3)|."""
    return max(SH_LOBE0 * abs(c[4 * ch]) + SH_LOBE1 * math.sqrt(sum(v * v for v in c[4 * ch + 1:4 * ch + 4]))
               for ch in range(3))


def _shq_bound_checks(held, exact, bound, n, what):
    """R5.16's bound: each of the n cells c~ of held (raw fp32 bytes)
    satisfies D(c~, c) <= bound x M(c), c exact's cell (NaN 0, clamped to
    1e30), to float rounding (1e-6 M + 1e-30; below 1e-30 a cell is held as
    zero). The bytes after the values (an index) must be exact's. Returns
    the largest D / (bound M) over the cells with M > 0."""
    check(len(held) == len(exact), "%s: %d bytes, the exact volume %d" % (what, len(held), len(exact)))
    check(held[48 * n:] == exact[48 * n:], "R5.16: %s: the %d bytes after the values differ from the exact volume's"
          % (what, len(exact) - 48 * n))
    a = struct.unpack_from("<%df" % (12 * n), held)
    e = [0.0 if v != v else min(max(v, -SHQ_VALUE_LIMIT), SHQ_VALUE_LIMIT)
         for v in struct.unpack_from("<%df" % (12 * n), exact)]
    worst = 0.0
    for i in range(n):
        c = e[12 * i:12 * i + 12]
        M = _shq_magnitude(c)
        D = _shq_magnitude([x - y for x, y in zip(a[12 * i:12 * i + 12], c)])
        check(D <= bound * M + 1e-6 * M + SHQ_TINY, "R5.16: %s: cell %d is D = %.6g from the exact volume's, over "
              "the bound %g x M = %g x %.6g" % (what, i, D, bound, bound, M))
        if M > 0.0:
            worst = max(worst, D / (bound * M))
    return worst
