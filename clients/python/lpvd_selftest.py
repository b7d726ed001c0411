"""lpvd_selftest.py - the lpvd Python client's self-test and command line:
``python3 lpvd_client.py --self-test ADDRESS`` runs ``main``, a short
end-to-end check against a running daemon (exit status 0 on success), after
the checks that need none; ``python3 lpvd_client.py --offline-self-test``
runs only those (SPEC R5.15's decoding and lookup on hand-made payloads).

Standard library only. One of the modules of the client; import
``lpvd_client``, which re-exports every name.

The protocol is protocol/SPEC.md; section numbers below refer to it.
"""

import json
import math
import struct
import sys

from lpvd_protocol import HAVE_ZSTD, LpvdError, ProtocolError, default_address, plan_lines
from lpvd_session import Client
from lpvd_volume import HAVE_NUMPY, IV_UNITS, LOOKUP_VALUES, LPV_UNITS, LayoutError, Volume


def _minimal_glb():
    """A tiny valid .glb: a 2 m floor quad and a back wall (no light: the
    server adds its default light, docs/units.md)."""
    pos = [-1, 0, -1, 1, 0, -1, 1, 0, 1, -1, 0, 1,
           -1, 0, -1, 1, 0, -1, 1, 2, -1, -1, 2, -1]
    nrm = [0, 1, 0] * 4 + [0, 0, 1] * 4
    idx = [0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7]
    bin_ = struct.pack("<24f", *pos) + struct.pack("<24f", *nrm) + struct.pack("<12H", *idx)
    while len(bin_) % 4:
        bin_ += b"\0"
    gltf = {
        "asset": {"version": "2.0"},
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0}}],
        "buffers": [{"byteLength": len(bin_)}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 96},
                        {"buffer": 0, "byteOffset": 96, "byteLength": 96},
                        {"buffer": 0, "byteOffset": 192, "byteLength": 24}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3",
             "min": [-1, 0, -1], "max": [1, 2, 1]},
            {"bufferView": 1, "componentType": 5126, "count": 8, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5123, "count": 12, "type": "SCALAR"},
        ],
    }
    js = json.dumps(gltf, separators=(",", ":")).encode()
    while len(js) % 4:
        js += b" "
    total = 12 + 8 + len(js) + 8 + len(bin_)
    return (struct.pack("<4sII", b"glTF", 2, total) + struct.pack("<I4s", len(js), b"JSON") + js
            + struct.pack("<I4s", len(bin_), b"BIN\0") + bin_)


def _self_test_iv(c, say):
    """SPEC R5.14 and R6.5: technique iv's volume decoded, its local lookup
    (iv_irradiance) against QUERY_IRRADIANCE, and the ao frame term."""
    try:
        c.get_frame(format="rgba8", terms="ao")
        raise AssertionError("terms \"ao\" without technique iv was not refused")
    except LpvdError as e:
        if e.name != "BAD_FIELD" or "terms" not in e.message:
            raise AssertionError("terms \"ao\" without technique iv: %s %s" % (e.name, e.message))
    c.config(technique="iv", iv_resolution=12, iv_rays=16, iv_bounces=2, iv_neighbours=6)
    t = c.tick()
    vol = c.get_volume(format="fp32")
    if not vol.iv or vol.units != IV_UNITS or vol.iv_neighbours != 6 or len(vol.index) != vol.cells \
            or vol.lookup_refusal is not None:
        raise AssertionError("iv volume: iv %r, units %r, iv_neighbours %r, index of %d for %d voxels, refusal %r" % (
            vol.iv, vol.units, vol.iv_neighbours, len(vol.index or ()), vol.cells, vol.lookup_refusal))
    held = sum(1 for h in vol.index if h)
    if not 0 < held < vol.cells:
        raise AssertionError("iv volume: %d of %d voxels hold a surface" % (held, vol.cells))
    try:
        vol.cascades[0].irradiance(vol.origin, (0, 1, 0))
        raise AssertionError("R5.7's lookup read technique iv's voxels")
    except LayoutError:
        pass
    # random points (a seeded generator: no two corners exactly as far from the
    # shifted point, a tie the server may break the other way, R5.14)
    import random
    rnd = random.Random(5)
    points, normals = [], []
    for i in range(120):
        points.append([vol.origin[a] + rnd.uniform(0.02, 0.98) * vol.dims[a] * vol.cell_size for a in range(3)])
        normals.append([(0.0, 1.0, 0.0), (1.0, 0.0, 0.0), (0.0, 0.0, -1.0)][i % 3] if i % 2 else
                       [rnd.uniform(-1.0, 1.0) for _ in range(3)])
    e = c.query_irradiance(points, normals)
    peak = max(max(float(v) for v in row) for row in e)
    worst = 0.0
    for p, n, row in zip(points, normals, e):
        for a, b in zip(vol.irradiance(p, n), row):
            worst = max(worst, abs(a - float(b)))
    if not peak > 0.0 or worst > 1e-4 * peak:
        raise AssertionError("iv: local lookup differs from QUERY_IRRADIANCE by %.3g of the peak %.4g W/m^2"
                             % (worst / max(peak, 1e-30), peak))
    st = t.get("stats", {}).get("iv") or {}
    say("GET_VOLUME technique iv -> %s voxels of %.4g m, %d hold a surface (stats: %s), iv_neighbours %d; local "
        "R5.14 lookup at %d points differs from QUERY_IRRADIANCE by %.2e of the peak %.4g W/m^2" % (
            "x".join(str(d) for d in vol.dims), vol.cell_size, held, st.get("occupied"), vol.iv_neighbours,
            len(points), worst / peak, peak))
    c.config(iv_ao=True)
    c.tick()
    fr = c.get_frame(format="rgba8", compression="none", terms="ao")
    if fr.header.get("units") != "1" or fr.header.get("terms") != "ao":
        raise AssertionError("ao frame header %r" % ({k: v for k, v in fr.header.items() if k != "plan"},))
    grey = all(fr.data[i] == fr.data[i + 1] == fr.data[i + 2] for i in range(0, len(fr.data), 4))
    if not grey:
        raise AssertionError("the ao frame is not grey")
    say("GET_FRAME terms ao -> %dx%d grey, units %s" % (fr.width, fr.height, fr.header.get("units")))


# -- offline: decoding and R5.15's lookup on hand-made payloads (no daemon) --

def _probes_reply(levels, I, D, bias, probe_values, fmt="fp32"):
    """A GET_VOLUME content "visibility" reply (header, raw bytes) of technique
    probes as SPEC R5.15 describes it: ``levels`` (dims, origin, cell_size)
    finest first, maps of sides I and D, ``probe_values(k, x, y, z)`` the V
    values of level k's probe at cell (x, y, z); the SH value of each cell's
    r.Y00 is its index (the rest 0)."""
    V = 4 + 3 * I * I + 2 * D * D
    cascades, sh, vis = [], [], []
    for k, (dims, origin, cs) in enumerate(levels):
        cells = dims[0] * dims[1] * dims[2]
        cascades.append({"dims": list(dims), "origin": list(origin), "cell_size": cs, "cells": cells})
        for i in range(cells):
            x, y, z = i % dims[0], (i // dims[0]) % dims[1], i // (dims[0] * dims[1])
            sh.extend([float(len(sh) // 12)] + [0.0] * 11)
            v = list(probe_values(k, x, y, z))
            if len(v) != V:
                raise AssertionError("synthetic probe of %d values, V = %d" % (len(v), V))
            vis.extend(v)
    P = len(vis) // V
    values = struct.pack("<%d%s" % (len(sh), "e" if fmt == "fp16" else "f"), *sh)
    raw = values + struct.pack("<%df" % len(vis), *vis)
    desc = {"layout_version": 1, "technique": "probes",
            "levels": [dict(c, role="cascade") for c in cascades], "far_field": False, "volumes_per_level": 1,
            "values_per_cell": 12, "values": list(LOOKUP_VALUES), "units": LPV_UNITS, "index": None,
            "visibility": {"probes": P, "irradiance_side": I, "distance_side": D, "values_per_probe": V,
                           "value_type": "f32", "bias_cells": bias, "raw_offset": len(values),
                           "raw_length": P * V * 4}}
    header = {"revision": 1, "tick": 1, "format": fmt, "compression": "none", "keyframe": True,
              "grid": {k: cascades[0][k] for k in ("dims", "origin", "cell_size")}, "cascades": cascades,
              "units": LPV_UNITS, "layout": "cell-major, x fastest; per cell r0 r1 r2 r3 g0 g1 g2 g3 b0 b1 b2 b3",
              "sh": "Y00, Y1-1 (y), Y10 (z), Y11 (x), no Condon-Shortley phase", "raw_length": len(raw),
              "plan": None, "volume": desc}
    return header, raw


def _probe(I, D, rgb=(0.0, 0.0, 0.0), active=1.0, offset=(0.0, 0.0, 0.0), irradiance=None, mean=2.0,
           mean2=None):
    """One probe's V values: ``irradiance`` a list of I^2 (r, g, b) texels
    (default: every texel rgb), every distance texel (mean, mean2) (default
    mean2 = mean^2)."""
    texels = irradiance if irradiance is not None else [rgb] * (I * I)
    out = list(offset) + [active]
    for t in texels:
        out.extend(t)
    for _ in range(D * D):
        out.extend((mean, mean * mean if mean2 is None else mean2))
    return out


def _close(a, b, tol=1e-9):
    return all(abs(x - y) <= tol * max(1.0, abs(y)) for x, y in zip(a, b))


def _offline_probes(say):
    """SPEC R5.15 without a daemon: a hand-made 2x2x2 (and two-level)
    visibility decoded and checked, the malformed ones refused, and the
    lookup against values worked out by hand."""
    import copy
    import lpvd_volume
    one = [((2, 2, 2), (0.0, 0.0, 0.0), 1.0)]
    I, D = 2, 3
    V = 4 + 3 * I * I + 2 * D * D
    # -- decoding, fp32 and fp16 (the visibility stays binary32)
    for fmt in ("fp32", "fp16"):
        hdr, raw = _probes_reply(one, I, D, 0.25, lambda k, x, y, z: _probe(
            I, D, irradiance=[(x + 0.5, y + 0.25, z + 0.125 * t) for t in range(I * I)], active=float(x != 1 or y),
            offset=(0.01 * x, -0.02 * y, 0.03 * z), mean=0.5 + z, mean2=0.3 + z), fmt)
        vol = Volume(hdr, raw, "visibility")
        vis = vol.visibility
        if vol.content != "visibility" or vis is None or (vis.probes, vis.irradiance_side, vis.distance_side,
                                                          vis.values_per_probe, vis.bias_cells) != (8, I, D, V, 0.25):
            raise AssertionError("%s visibility decoded as content %r, %r" % (fmt, vol.content, vis and (
                vis.probes, vis.irradiance_side, vis.distance_side, vis.values_per_probe, vis.bias_cells)))
        if vol.cells != 8 or vol.cell(1, 0, 0)[0] != 1.0 or vol.cell(1, 1, 1)[0] != 7.0:
            raise AssertionError("%s: the SH values before the visibility decode wrongly" % fmt)
        for i in range(8):
            x, y, z = i % 2, (i // 2) % 2, i // 4
            want = _probe(I, D, irradiance=[(x + 0.5, y + 0.25, z + 0.125 * t) for t in range(I * I)],
                          active=float(x != 1 or y), offset=(0.01 * x, -0.02 * y, 0.03 * z), mean=0.5 + z,
                          mean2=0.3 + z)
            got = vis.probe(i)
            if len(got) != V or not _close(got, [struct.unpack("<f", struct.pack("<f", w))[0] for w in want], 0):
                raise AssertionError("%s: probe %d decoded as %r, built as %r" % (fmt, i, got[:8], want[:8]))
        if vis.active is not None and ([float(a) for a in vis.active] != [1, 0, 1, 1, 1, 0, 1, 1]
                                       or vis.irradiance.shape != (8, I * I, 3) or vis.distance.shape != (8, D * D, 2)
                                       or abs(float(vis.distance[7, 8, 1]) - 1.3) > 1e-6
                                       or abs(float(vis.offsets[7, 2]) - 0.03) > 1e-8):
            raise AssertionError("%s: the numpy views of the visibility disagree with the values" % fmt)
    # -- refusals (R5.15: anywhere but content "visibility", and any disagreeing count)
    hdr, raw = _probes_reply(one, I, D, 0.25, lambda k, x, y, z: _probe(I, D, (1.0, 2.0, 3.0)))
    for content in (None, "merged", "levels"):
        try:
            Volume(hdr, raw, content)
            raise AssertionError("a visibility in a reply to content %r was read" % (content,))
        except ProtocolError as e:
            if "visibility" not in str(e):
                raise AssertionError("the refusal does not name the visibility: %s" % e)
    plain = copy.deepcopy(hdr)
    del plain["volume"]["visibility"]
    plain["raw_length"] = hdr["volume"]["visibility"]["raw_offset"]
    Volume(plain, raw[:plain["raw_length"]])  # the merged volume alone reads
    bad = [("probes", 9), ("probes", 8.0), ("irradiance_side", 0), ("irradiance_side", 17), ("distance_side", 33),
           ("distance_side", 0), ("values_per_probe", V + 1), ("value_type", "f16"), ("bias_cells", -0.5),
           ("bias_cells", "0.25"), ("raw_offset", hdr["volume"]["visibility"]["raw_offset"] + 4),
           ("raw_length", 8 * V * 4 - 4), ("raw_length", None)]
    wrong = [("content visibility without one", plain, raw[:plain["raw_length"]])]
    for key, value in bad:
        h = copy.deepcopy(hdr)
        h["volume"]["visibility"][key] = value
        wrong.append(("visibility.%s %r" % (key, value), h, raw))
    for what, change in (("header raw_length", lambda h: h.update(raw_length=h["raw_length"] + 4)),
                         ("not a keyframe", lambda h: h.update(keyframe=False, base_tick=0)),
                         ("far_field true", lambda h: h["volume"].update(far_field=True)),
                         ("visibility not an object", lambda h: h["volume"].update(visibility=[8]))):
        h = copy.deepcopy(hdr)
        change(h)
        wrong.append((what, h, raw))
    wrong.append(("a short attachment", hdr, raw[:-4]))
    for what, h, r in wrong:
        try:
            Volume(h, r, "visibility")
            raise AssertionError("R5.15: %s was read" % what)
        except ProtocolError:
            pass
    try:
        Volume(plain, raw[:plain["raw_length"]]).probes_irradiance((1, 1, 1), (0, 0, 1))
        raise AssertionError("R5.15's lookup read a volume without the visibility")
    except LayoutError as e:
        if "probes" not in str(e) or "merged" not in str(e) or "visibility" not in str(e):
            raise AssertionError("the refusal does not name technique, content and visibility: %s" % e)
    # -- the lookup
    # a. identical constant maps: E is that irradiance wherever p is and whatever the weights
    vol = Volume(hdr, raw, "visibility")
    for p, n in (((1.0, 1.0, 1.0), (0, 0, 1)), ((0.3, 1.7, 0.9), (1, -2, 0.5)), ((5.0, -3.0, 1.0), (0, 1, 0))):
        if not _close(vol.irradiance(p, n), (1.0, 2.0, 3.0)):
            raise AssertionError("identical maps (1, 2, 3): E at %r facing %r is %r" % (p, n, vol.irradiance(p, n)))
    for p, n in (((1, 1, 1), (0, 0, 0)), ((1, 1, 1), (0, 1e-9, 0)), ((float("nan"), 1, 1), (0, 1, 0)),
                 ((1, 1, 1), (float("inf"), 0, 0))):
        if vol.irradiance(p, n) != (0.0, 0.0, 0.0):
            raise AssertionError("E at %r facing %r is %r, R5.15 says 0" % (p, n, vol.irradiance(p, n)))
    # b. the octahedral map read bilinearly: texel t's red = t + 1 on a 2 x 2 map (by hand: +z reads the
    # four texels' mean, +x the column 1 (texels 1, 3), -x column 0 (0, 2), +y row 1 (2, 3), -z folds to
    # the corner texel 3)
    hdr_b, raw_b = _probes_reply(one, I, D, 0.25, lambda k, x, y, z: _probe(
        I, D, irradiance=[(t + 1.0, 0.0, 0.0) for t in range(4)]))
    vol_b = Volume(hdr_b, raw_b, "visibility")
    for n, want in (((0, 0, 1), 2.5), ((1, 0, 0), 3.0), ((-1, 0, 0), 2.0), ((0, 1, 0), 3.5), ((0, 0, -1), 4.0),
                    ((0, -1, 0), 1.5)):
        got = vol_b.irradiance((1.0, 1.0, 1.0), n)
        if not _close(got, (want, 0.0, 0.0)):
            raise AssertionError("2x2 irradiance map read toward %r: %r, by hand %r" % (n, got, want))
    # b2. a 4 x 4 map whose red is column + 10 row: read bilinearly inside it, E = s_x + 10 s_y, s the
    # clamped place of oct(n) (by hand: +z (0, 0) -> (1.5, 1.5); +x (1, 0) -> (3, 1.5); -y (0, -1) ->
    # (1.5, 0); (1, 2, -1) (0.25, 0.5) folds to (0.5, 0.75) -> (2.5, 3); (-1, 0, -1) (-0.5, 0) folds to
    # (-1, 0.5), sgn 0 = +1 -> (0, 2.5))
    hdr_b, raw_b = _probes_reply(one, 4, D, 0.25, lambda k, x, y, z: _probe(
        4, D, irradiance=[(t % 4 + 10.0 * (t // 4), 1.0, 0.0) for t in range(16)]))
    vol_b = Volume(hdr_b, raw_b, "visibility")
    for n, want in (((0, 0, 1), 16.5), ((1, 0, 0), 18.0), ((0, -1, 0), 1.5), ((1, 2, -1), 32.5), ((-1, 0, -1), 25.0)):
        got = vol_b.irradiance((0.7, 1.2, 0.4), n)
        if not _close(got, (want, 1.0, 0.0)):
            raise AssertionError("4x4 irradiance map read toward %r: %r, by hand %r" % (n, got, want))
    # c. a wall: the probes at x = 1 see a surface 0.1 m away (mean 0.1, mean square 0.01) while the point
    # (1, 1, 1), bias 0, is sqrt(0.75) m from each: their Chebyshev weight is ~1e-4 ^ 3, crushed, floored
    # at 1e-6; the probes at x = 0 see 2 m. Red from the open side, green from behind the wall. Then a
    # probe half hidden (mean 0.5, mean square 0.29: sigma^2 0.04): Chebyshev 0.04 / (0.04 + (d - 0.5)^2)
    # cubed, the front probes' weight crushed to w^3 / 0.04, the back ones' floored at 1e-6.
    f32 = lpvd_volume._f32
    t = 0.125  # each corner's trilinear weight at the cells' common corner
    front, back = (1 + 1 / math.sqrt(3)) / 2, (1 - 1 / math.sqrt(3)) / 2  # phi toward a probe at z 1.5 / 0.5
    wl = 2 * t * ((front ** 2 + 0.2) + (back ** 2 + 0.2))  # the two open probes of each z, uncrushed (>= 0.2)
    for mean, mean2 in ((0.1, 0.01), (0.5, 0.29), (0.85, 0.7225)):  # the last: sigma^2 its floor, 1e-4 s^2
        cheb = 1.0
        if math.sqrt(0.75) > f32(mean):
            var = max(f32(mean2) - f32(mean) ** 2, 1e-4)
            cheb = (var / (var + (math.sqrt(0.75) - f32(mean)) ** 2)) ** 3
        wr = 0.0
        for phi in (front, back):
            w = (phi ** 2 + 0.2) * cheb
            w = w ** 3 / 0.04 if w < 0.2 else w
            wr += 2 * t * max(w, 1e-6)
        for side in (1, D):  # a one-texel distance map, and D^2 texels (all alike)

            def walled(k, x, y, z, left_active=1.0):
                if x == 0:
                    return _probe(I, side, (10.0, 0.0, 0.0), active=left_active, mean=2.0)
                return _probe(I, side, (0.0, 10.0, 0.0), mean=mean, mean2=mean2)
            hdr_c, raw_c = _probes_reply(one, I, side, 0.0, walled)
            vol_c = Volume(hdr_c, raw_c, "visibility")
            got = vol_c.irradiance((1.0, 1.0, 1.0), (0, 0, 1))
            want = (10.0 * wl / (wl + wr), 10.0 * wr / (wl + wr), 0.0)
            if not _close(got, want, 1e-6):
                raise AssertionError("probes behind a wall (mean %g, mean square %g, %d^2 texels): E %r, by hand %r"
                                     % (mean, mean2, side, got, want))
            if mean == 0.1:
                wall = got
    # without the Chebyshev weight the walled probes would weigh as much as the open ones: (5, 5, 0)
    # d. the open probes off: only the walled ones remain; h < 1e-3 but there is no coarser level, so E
    # is theirs, normalised
    hdr_d, raw_d = _probes_reply(one, I, D, 0.0, lambda k, x, y, z: _probe(
        I, D, (10.0, 0.0, 0.0), active=0.0) if x == 0 else _probe(I, D, (0.0, 10.0, 0.0), mean=0.1, mean2=0.01))
    got = Volume(hdr_d, raw_d, "visibility").irradiance((1.0, 1.0, 1.0), (0, 0, 1))
    if not _close(got, (0.0, 10.0, 0.0)):
        raise AssertionError("only walled probes active: E %r, expected theirs (0, 10, 0)" % (got,))
    # d2. two probes on a 2 x 1 x 1 level (cell 1 m, so the corners with a y or z bit weigh 0), each moved
    # by its offset: red at (0.6, 0.5, 0.5), green at (1.5, 0.7, 0.5) whose distance map is 2 x 2 with
    # mean 0.1 (mean square 0.02: sigma^2 0.01) in the column facing -x and 2 m in the other. The point
    # (1, 0.6, 0.5) facing +x with bias 0.25 looks up from x = (1.25, 0.6, 0.5): trilinear 0.25 / 0.75;
    # phi from p toward each probe; v = x - m toward the green probe reads the -x column
    def pair(k, x, y, z):
        if x == 0:
            return _probe(I, 2, (10.0, 0.0, 0.0), offset=(0.1, 0.0, 0.0), mean=2.0)
        # texels t = row * 2 + column: (0.1, 0.02) in column 0, (2, 4) in column 1
        return _probe(I, 2, (0.0, 10.0, 0.0), offset=(0.0, 0.2, 0.0))[:4 + 3 * I * I] + [0.1, 0.02, 2.0, 4.0] * 2
    hdr_p, raw_p = _probes_reply([((2, 1, 1), (0.0, 0.0, 0.0), 1.0)], I, 2, 0.25, pair)
    p_, x_ = (1.0, 0.6, 0.5), (1.25, 0.6, 0.5)
    ws = []
    for m, t in (((0.6, 0.5, 0.5), 0.25), ((1.5, 0.7, 0.5), 0.75)):
        r = [m[a] - p_[a] for a in range(3)]
        phi = (r[0] / math.sqrt(sum(c * c for c in r)) + 1) / 2  # n = +x
        w = phi * phi + 0.2
        delta = math.sqrt(sum((x_[a] - m[a]) ** 2 for a in range(3)))
        if m[0] == 1.5 and delta > f32(0.1):  # the -x column: mean 0.1
            var = f32(0.02) - f32(0.1) ** 2
            w *= (var / (var + (delta - f32(0.1)) ** 2)) ** 3
        w = w ** 3 / 0.04 if w < 0.2 else w
        ws.append(max(w, 1e-6) * t)
    want = (10.0 * ws[0] / sum(ws), 10.0 * ws[1] / sum(ws), 0.0)
    got = Volume(hdr_p, raw_p, "visibility").irradiance(p_, (1, 0, 0))
    if not _close(got, want, 1e-6):
        raise AssertionError("two probes moved by their offsets, one half hidden toward the point: E %r, by hand %r"
                             % (got, want))
    # e. two levels: level 0 red (cell 1 m at the origin), level 1 blue (cell 2 m from -1): at (1, 1, 1)
    # level 0 is asked (inside 1 cell >= 1/2) and blended with w = (1 - 1/2) / 2 = 1/4; level 0's
    # probes off: level 1 alone; outside level 0's last probes: level 1 alone
    two = one + [((2, 2, 2), (-1.0, -1.0, -1.0), 2.0)]

    def levels(k, x, y, z, on=1.0):
        return _probe(I, D, (10.0, 0.0, 0.0), active=on) if k == 0 else _probe(I, D, (0.0, 0.0, 10.0), mean=4.0)
    hdr_e, raw_e = _probes_reply(two, I, D, 0.25, levels)
    vol_e = Volume(hdr_e, raw_e, "visibility")
    for p, want in (((1.0, 1.0, 1.0), (2.5, 0.0, 7.5)), ((1.0, 0.3, 1.0), (0.0, 0.0, 10.0)),
                    ((2.5, 1.0, 1.0), (0.0, 0.0, 10.0)), ((1.0, 0.75, 1.0), (10 * 0.125, 0.0, 10 * 0.875))):
        got = vol_e.irradiance(p, (0, 1, 0))
        if not _close(got, want):
            raise AssertionError("two levels at %r: E %r, by hand %r" % (p, got, want))
    hdr_f, raw_f = _probes_reply(two, I, D, 0.25, lambda k, x, y, z: levels(k, x, y, z, 0.0))
    got = Volume(hdr_f, raw_f, "visibility").irradiance((1.0, 1.0, 1.0), (0, 1, 0))
    if not _close(got, (0.0, 0.0, 10.0)):
        raise AssertionError("level 0's probes off: E %r, expected level 1's (0, 0, 10)" % (got,))
    # level 1's probes off: level 0 is not blended with a level that does not see p
    hdr_g, raw_g = _probes_reply(two, I, D, 0.25, lambda k, x, y, z: levels(k, x, y, z) if k == 0 else _probe(
        I, D, (0.0, 0.0, 10.0), active=0.0))
    got = Volume(hdr_g, raw_g, "visibility").irradiance((1.0, 1.0, 1.0), (0, 1, 0))
    if not _close(got, (10.0, 0.0, 0.0)):
        raise AssertionError("level 1's probes off: E %r, expected level 0's alone (10, 0, 0)" % (got,))
    say("offline R5.15 (numpy: %s): a hand-made visibility decoded in fp32 and fp16, %d malformed replies refused, "
        "the lookup agrees with values worked out by hand (maps, levels, a probe behind a wall: E %.6g red, %.2g "
        "green)" % (lpvd_volume._np is not None, len(wrong) + 3, wall[0], wall[1]))


def offline_self_test(out=sys.stdout):
    """The client's checks that need no daemon (SPEC R5.15's decoding and
    lookup on hand-made payloads), with numpy when it is importable and
    again without it. Returns 0 on success, raises AssertionError."""
    import lpvd_volume

    def say(msg):
        out.write("self-test: %s\n" % msg)
        out.flush()
    np_ = lpvd_volume._np
    try:
        for np_now in ([np_, None] if np_ is not None else [None]):
            lpvd_volume._np = np_now
            _offline_probes(say)
    finally:
        lpvd_volume._np = np_
    return 0


def _self_test_probes(c, say):
    """SPEC R5.15: technique probes' GET_VOLUME content "visibility" decoded
    (fp32 and fp16), its merged part equal to the merged volume, and the
    local lookup (probes_irradiance) against QUERY_IRRADIANCE."""
    c.config(technique="probes", grid=[8, 8, 8])
    c.tick()
    vol = c.get_volume(format="fp32", content="visibility")
    merged = c.get_volume(format="fp32")
    vis = vol.visibility
    if vis is None or vol.content != "visibility" or merged.visibility is not None or vol.technique != "probes":
        raise AssertionError("content visibility: technique %r, content %r, visibility %r (merged: %r)" % (
            vol.technique, vol.content, vis, merged.visibility))
    if vol.tick != merged.tick or vol.raw[:vis.description["raw_offset"]] != merged.raw:
        raise AssertionError("content visibility's volume differs from the merged one of tick %r" % merged.tick)
    vol16 = c.get_volume(format="fp16", content="visibility")
    if vol16.raw[vol16.visibility.description["raw_offset"]:] != vol.raw[vis.description["raw_offset"]:]:
        raise AssertionError("the fp16 reply's visibility differs from the fp32 one's (R5.15: binary32 in both)")
    try:
        merged.probes_irradiance(merged.origin, (0, 1, 0))
        raise AssertionError("R5.15's lookup read a volume without the visibility")
    except LayoutError:
        pass
    import random
    rnd = random.Random(15)
    points, normals = [], []
    for i in range(90):
        points.append([vol.origin[a] + rnd.uniform(0.02, 0.98) * vol.dims[a] * vol.cell_size for a in range(3)])
        normals.append([(0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (-1.0, 0.0, 0.0)][i % 3] if i % 2 else
                       [rnd.uniform(-1.0, 1.0) for _ in range(3)])
        ln = math.sqrt(sum(v * v for v in normals[-1]))
        normals[-1] = [v / ln for v in normals[-1]]
    e = c.query_irradiance(points, normals)
    local = [vol.irradiance(p, n) for p, n in zip(points, normals)]
    peak = max(max(max(float(v) for v in row) for row in e), max(max(row) for row in local))
    errs = [max(abs(a - float(b)) for a, b in zip(mine, row)) for mine, row in zip(local, e)]
    close = sum(1 for x in errs if x <= 1e-4 * peak)
    if not peak > 0.0 or close < 0.9 * len(points) or max(errs) > 2e-2 * peak:
        raise AssertionError("probes: %d of %d points agree with QUERY_IRRADIANCE within 1e-4 of the peak %.4g W/m^2 "
                             "(R5.15), the worst by %.3g of it" % (close, len(points), peak, max(errs) / peak))
    say("GET_VOLUME content visibility (probes) -> %d probes, maps %d^2 / %d^2, %d on; local R5.15 lookup at %d "
        "points: %d within 1e-4 of the peak %.4g W/m^2 of QUERY_IRRADIANCE, the worst %.2e" % (
            vis.probes, vis.irradiance_side, vis.distance_side,
            sum(1 for i in range(vis.probes) if vis.probe(i)[3] != 0.0), len(points), close, peak,
            max(errs) / peak))


def self_test(address, token=None, glb=None, out=sys.stdout):
    """The offline checks, then hello, (scene), tick, get_volume, query,
    stats, bye. Returns 0 on success."""
    def say(msg):
        out.write("self-test: %s\n" % msg)
        out.flush()

    offline_self_test(out)

    c = Client(address, token=token, client_name="lpvd_client.py self-test", timeout=120)
    say("HELLO -> %s" % json.dumps(c.hello_reply, sort_keys=True))
    if c.hello_reply.get("version") != 1:
        raise AssertionError("HELLO reply version %r" % c.hello_reply.get("version"))
    knobs = c.knobs
    if not knobs or "normal_bins" not in knobs or "far_field" not in knobs:
        raise AssertionError("HELLO describes no normal_bins / far_field knobs: %r" % sorted(knobs))
    for k in knobs.values():  # every default passes the client's own check of the description
        Client.knob_value(k, k["default"])
    try:
        c.config(damping=knobs["damping"]["max"] + 1)
        raise AssertionError("a damping above the described range was sent")
    except ValueError as e:
        if "damping" not in str(e):
            raise AssertionError("the refusal does not name damping: %s" % e)
    say("HELLO describes %d knobs and the presets %s" % (len(knobs), ", ".join(c.presets)))
    # The local lookup below is R5.7's on the cascaded LPV's volume (named:
    # lpvd's default technique is auto since issue 30, whose volume is mostly
    # iv's voxels, R5.14, tested in _self_test_iv): exact for one volume per
    # cascade, so normal bins and the far field (the LPV's defaults) are off
    # (docs/protocol.md, "Volumes and the defaults").
    c.config(technique="lpv", normal_bins=False, far_field=False)
    if glb is not None:
        with open(glb, "rb") as f:
            r = c.scene_load_glb(f.read())
        say("SCENE_LOAD (%s) -> revision %s, scene %s" % (glb, r.get("revision"), json.dumps(r.get("scene"))))
    # A reply to an unloaded session may be NOT_READY: load a small scene then.
    try:
        t = c.tick()
    except LpvdError as e:
        if e.name != "NOT_READY":
            raise
        say("TICK -> NOT_READY (%s); loading a built-in minimal .glb" % e.message)
        r = c.scene_load_glb(_minimal_glb())
        say("SCENE_LOAD (minimal glb) -> revision %s" % r.get("revision"))
        t = c.tick()
    say("TICK -> tick %s, revision %s" % (t.get("tick"), t.get("revision")))
    vol = c.get_volume(format="fp32")
    flux = vol.total_flux()
    say("GET_VOLUME -> dims %s, cell %.4g m, tick %s, total flux %s W"
        % (list(vol.dims), vol.cell_size, vol.tick, ["%.4g" % v for v in flux]))
    say("GET_VOLUME cascades -> %s" % ", ".join("%s cells of %.4g m at %s" % (
        "x".join(str(d) for d in cc.dims), cc.cell_size, ["%.4g" % v for v in cc.origin]) for cc in vol.cascades))
    d = vol.description
    say("GET_VOLUME description -> layout %s, technique %s, %d values per cell %s, %d volume(s) per level, "
        "far field %s, roles %s" % (d["layout_version"], d["technique"], d["values_per_cell"], d["values"],
                                    d["volumes_per_level"], d["far_field"], [lv["role"] for lv in d["levels"]]))
    if vol.lookup_refusal is not None:
        raise AssertionError("the daemon's volume is not the lookup's layout: %s" % vol.lookup_refusal)
    if vol.cells <= 0:
        raise AssertionError("empty volume")
    if not all(v == v and v >= 0 for v in flux):
        raise AssertionError("volume flux %r is not finite and non-negative" % flux)
    vol16 = c.get_volume(format="fp16")
    if vol16.dims != vol.dims:
        raise AssertionError("fp16 volume dims %r != fp32 dims %r" % (vol16.dims, vol.dims))
    # Points through the middle of the grid, facing each axis direction.
    centre = [vol.origin[a] + 0.5 * vol.dims[a] * vol.cell_size for a in range(3)]
    normals = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
    points = [tuple(centre)] * len(normals)
    e = c.query_irradiance(points, normals)
    worst = 0.0
    for i in range(len(normals)):
        local = vol.irradiance(points[i], normals[i])
        server = [float(v) for v in e[i]]
        for a, b in zip(local, server):
            worst = max(worst, abs(a - b) / max(1e-6, abs(a), abs(b)))
    say("QUERY_IRRADIANCE at the grid centre -> %s W/m^2; local lookup differs by %.2e (relative)"
        % (["%.4g,%.4g,%.4g" % tuple(float(v) for v in e[i]) for i in range(len(normals))], worst))
    for row in e:
        for v in row:
            if not (v == v and v >= 0):
                raise AssertionError("irradiance %r is not finite and non-negative" % (v,))
    if worst > 1e-3:
        raise AssertionError("server and local irradiance disagree (%.3g relative)" % worst)
    fr = c.get_frame(format="png")
    if fr.format != "png" or fr.data[:8] != b"\x89PNG\r\n\x1a\n":
        raise AssertionError("GET_FRAME png returned %r (%d bytes)" % (fr.format, len(fr.data)))
    say("GET_FRAME png -> %dx%d, %d bytes" % (fr.width, fr.height, len(fr.data)))
    # Volume stream with XOR deltas: each rebuilt volume equals a keyframe of the same tick.
    c.subscribe("volume", format="fp16", delta=True)
    kinds = []
    for i in range(3):
        if i == 2:  # change something, so the last delta is not all zeros
            c.light_set("self-test", "point", 0.5, position=centre)
        t = c.tick()
        sv = c.next_message()
        if not isinstance(sv, Volume) or sv.tick != t.get("tick"):
            raise AssertionError("stream gave %r for tick %r" % (sv, t.get("tick")))
        key = c.get_volume(format="fp16")
        if key.tick != sv.tick or key.raw != sv.raw:
            raise AssertionError("streamed volume of tick %s differs from GET_VOLUME's" % sv.tick)
        kinds.append("keyframe" if sv.keyframe else "delta/%s" % sv.base_tick)
    c.unsubscribe("volume")
    say("VOLUME stream (fp16, delta) -> %s, each equal to GET_VOLUME of its tick" % ", ".join(kinds))
    # SPEC R5.15: the probes' visibility only from technique probes
    try:
        c.get_volume(content="visibility")
        raise AssertionError("content \"visibility\" from technique %r was not refused" % vol.technique)
    except LpvdError as e:
        if e.name != "BAD_FIELD" or "content" not in e.message:
            raise AssertionError("content \"visibility\" without probes: %s %s" % (e.name, e.message))
    # SPEC R5.13: an octree's levels and index (GET_VOLUME content "levels")
    try:
        c.get_volume(content="levels")
        raise AssertionError("content \"levels\" from technique %r was not refused" % vol.technique)
    except LpvdError as e:
        if e.name != "BAD_FIELD" or "content" not in e.message:
            raise AssertionError("content \"levels\" without levels: %s %s" % (e.name, e.message))
    if "octree" in (c.hello_reply.get("techniques") or []):
        c.config(technique="octree", grid=[8, 8, 8])
        c.tick()
        merged, lv = c.get_volume(format="fp32"), c.get_volume(format="fp32", content="levels")

        def flat(a):
            return [float(v) for v in (a.reshape(-1) if hasattr(a, "reshape") else a)]
        m, n = flat(merged.data), 8
        if lv.content != "levels" or merged.content != "merged" or len(lv.levels) != 4 or len(lv.cascades) != 1:
            raise AssertionError("content levels: %r with %d levels, %d cascades" % (
                lv.content, len(lv.levels), len(lv.cascades)))
        data = [flat(level.data) for level in lv.levels]
        for cell, i in enumerate(lv.index):  # eq. 10: merged(x) = level I(x) at x >> I(x)
            x, y, z, k = cell % n, (cell // n) % n, cell // (n * n), n >> i
            at = 12 * ((x >> i) + k * ((y >> i) + k * (z >> i)))
            if m[12 * cell:12 * cell + 12] != data[i][at:at + 12]:
                raise AssertionError("merged cell %d is not level %d's cell at x >> %d" % (cell, i, i))
        try:
            lv.irradiance(lv.origin, (0, 1, 0))
            raise AssertionError("the lookup read a \"levels\" volume")
        except LayoutError:
            pass
        say("GET_VOLUME content levels (octree) -> %s, index of %d, merged = the indexed levels" % (
            ", ".join("%d^3" % level.dims[0] for level in lv.levels), len(lv.index)))
    if "probes" in (c.hello_reply.get("techniques") or []):
        _self_test_probes(c, say)
    if "iv" in (c.hello_reply.get("techniques") or []):
        _self_test_iv(c, say)
    st = c.stats()
    say("STATS -> keys %s" % sorted(st.keys()))
    for line in plan_lines((st.get("plan") or {}).get("plan")):
        say("STATS plan: %s" % line)
    c.bye()
    say("BYE -> ok")
    return 0


def main(argv):
    import argparse
    ap = argparse.ArgumentParser(description="lpvd Python client")
    ap.add_argument("--self-test", metavar="ADDRESS", nargs="?", const="",
                    help="run a short end-to-end check against the daemon at ADDRESS")
    ap.add_argument("--token-file", help="file holding the token for HELLO")
    ap.add_argument("--glb", help="a .glb to load (self-test) before ticking")
    ap.add_argument("--offline-self-test", action="store_true",
                    help="run only the checks that need no daemon (decoding and lookups on hand-made payloads)")
    args = ap.parse_args(argv)
    if args.offline_self_test:
        try:
            rc = offline_self_test()
        except (ProtocolError, AssertionError, ValueError, LayoutError) as e:
            sys.stderr.write("offline self-test FAILED: %s: %s\n" % (type(e).__name__, e))
            return 1
        print("offline self-test passed (numpy: %s)" % HAVE_NUMPY)
        return rc
    token = None
    if args.token_file:
        with open(args.token_file) as f:
            token = f.read().strip()
    if args.self_test is None:
        ap.print_help()
        return 2
    address = args.self_test or default_address()
    try:
        rc = self_test(address, token=token, glb=args.glb)
    except (LpvdError, ProtocolError, OSError, AssertionError, ValueError, LayoutError) as e:
        sys.stderr.write("self-test FAILED: %s: %s\n" % (type(e).__name__, e))
        return 1
    print("self-test passed (numpy: %s, zstandard: %s)" % (HAVE_NUMPY, HAVE_ZSTD))
    return rc
