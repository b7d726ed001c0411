"""lpvd_selftest.py - the lpvd Python client's self-test and command line:
``python3 lpvd_client.py --self-test ADDRESS`` runs ``main``, a short
end-to-end check against a running daemon (exit status 0 on success), after
the checks that need none; ``python3 lpvd_client.py --offline-self-test``
runs only those (SPEC R5.15's decoding and lookup, R5.16's shq decoding,
on hand-made payloads).

Standard library only. One of the modules of the client; import
``lpvd_client``, which re-exports every name.

The protocol is protocol/SPEC.md; section numbers below refer to it.
"""

import json
import math
import struct
import sys

from lpvd_protocol import HAVE_ZSTD, LpvdError, ProtocolError, default_address, plan_lines, zstd_decoder
from lpvd_session import Client
from lpvd_volume import (HAVE_NUMPY, IV_UNITS, LOOKUP_VALUES, LPV_UNITS, SH_LOBE0, SH_LOBE1, SHQ_BOUND_MAX, LayoutError,
                         Volume, shq_bound_excess, shq_cell_distance, shq_cell_magnitude, shq_decode,
                         shq_decode_payload, shq_distances)


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


# -- offline: compression "shq" (SPEC R5.16) on hand-made payloads -----------

def _shq_payload(sent, extra=b"", bitmap=None, cells=None, flags=None, counts=None, magic=b"SHQ1", modes=None):
    """An R5.16 payload built by hand: ``sent`` the cells sent, in cell order,
    each (x, [12 mantissas r]); ``bitmap`` a delta's bit map (None: a
    keyframe); ``modes`` a delta's mode per cell sent (default: all 0, the
    mantissas are the values' steps; a keyframe has none); ``cells`` C
    (default: the cells sent); ``flags`` and ``counts`` (C, S, X) replace
    what the rest says, for the refusals."""
    S = len(sent)
    C, S_, X = counts or (S if cells is None else cells, S, len(extra))
    head = struct.pack("<4sIQQQ", magic, (1 if bitmap is None else 0) if flags is None else flags, C, S_, X)
    zz = [[2 * q if q >= 0 else -2 * q - 1 for q in qs] for _, qs in sent]
    lo = bytes(zz[j][k] & 0xFF for k in range(12) for j in range(S))
    hi = bytes(zz[j][k] >> 8 for k in range(12) for j in range(S))
    mode_bytes = b"" if bitmap is None else bytes([0] * S if modes is None else modes)
    return (head + (bitmap or b"") + struct.pack("<%db" % S, *[x for x, _ in sent]) + mode_bytes + lo + hi
            + extra)


def _shq_value(x, q, b=None):
    """Value q x 2^x as R5.16 says, in binary32 bytes: 0 for x = -128, infinity
    past the largest binary32 (worked out with ** and struct, not as the
    decoders do). ``b``: a delta's mode 1, the base's value (a binary32,
    finite): q is then the mantissa plus b x 2^-x rounded half to even."""
    if x == -128:
        return struct.pack("<f", 0.0)
    if b is not None:
        steps = b * 2.0 ** -x  # exact: |b| < 2^128, 2^-x <= 2^127
        near = math.floor(steps)
        near += 1 if steps - near > 0.5 or (steps - near == 0.5 and near % 2) else 0
        q += near
    try:
        return struct.pack("<f", q * 2.0 ** x)
    except OverflowError:
        return struct.pack("<f", math.copysign(float("inf"), q))


def _zstd_raw_frame(data):
    """``data`` as one zstd frame of raw (stored) blocks (RFC 8878 3.1.1): what
    the server's zstd frames decode to, built without a compressor."""
    out = struct.pack("<IB", 0xFD2FB528, 0xE0) + struct.pack("<Q", len(data))  # single segment, 8-byte size
    at = 0
    while True:
        block = data[at:at + 65536]
        at += len(block)
        out += struct.pack("<I", (len(block) << 3) | (1 if at >= len(data) else 0))[:3] + block
        if at >= len(data):
            return out


def _offline_shq(say):
    """SPEC R5.16 without a daemon: a hand-made keyframe and delta decoded to
    the values worked out by hand (through the session's delta bases and
    zstd when a zstd decoder is there), a seeded payload of every exponent
    against values computed another way, each rejection the SPEC names, and
    D and M against values worked out by hand. Returns the seeded payload's
    decoded bytes, which must not depend on numpy."""
    import random
    import lpvd_volume
    # -- a keyframe of 3 cells and an 8-byte index: a zero cell (x = -128), the extreme mantissas, a
    # subnormal (2^-127 x 1), a normal just above (3 x 2^-127), overflow to infinity (x = 127)
    q1 = [5, -3, 0, 1, 32767, -32768, 7, -1, 2, 0, 0, 9]
    key_cells = [(-3, q1), (-128, [1] * 12), (-127, [1, 3, -1, 0, 0, 0, 0, 0, 0, 0, 0, 0]),
                 (127, [0, 1, -1, 2, -3] + [0] * 7)]
    index = b"\x01\x00\x00\x00\x00\x00\x00\x00"
    want = b"".join(_shq_value(x, q) for x, qs in key_cells for q in qs) + index
    got = shq_decode_payload(_shq_payload(key_cells, index), len(want), 4, True)
    if got != want:
        raise AssertionError("shq keyframe decoded as %r, by hand %r" % (got[:48], want[:48]))
    if struct.unpack_from("<6f", got, 0)[::4] != (0.625, 32767 * 0.125) or struct.unpack_from("<f", got, 20) != (
            -4096.0,) or struct.unpack_from("<4f", got, 148) != (2.0 ** 127, -2.0 ** 127, math.inf, -math.inf):
        raise AssertionError("shq keyframe: q x 2^x is not 5/8, 32767/8, -32768/8, +-2^127, +-inf: %r, %r"
                             % (struct.unpack_from("<6f", got), struct.unpack_from("<4f", got, 148)))
    # -- a delta of 10 cells (a 2-byte bit map) re-sending cells 1, 3, 5, 6, 8 and 9 against a base of values
    # i - 60 (value i of the volume); the index XOR'd. Cells 1, 6 (x = -128: zero), 8 and 9 are mode 0, the
    # values' steps; cells 3 and 5 mode 1, the change from the base's cell in steps of 2^x: cell 3's base
    # -24..-13 at x = 1 has the negative ties -11.5, -10.5, ..., -6.5 (to -12, -10, -10, -8, -8, -6), cell 5's
    # 0..11 at x = 2 the ties 0.5, 1.5, 2.5 (to 0, 2, 2)
    base = struct.pack("<120f", *[float(i - 60) for i in range(120)]) + b"\x0f\x00\xf0\x00"
    resent = [(0, [1] * 12), (1, [0] * 10 + [1, -1]), (2, [0] * 11 + [3]), (-128, [5] * 12), (-2, [-2] * 12),
              (4, list(range(12)))]
    resent_at, modes, bitmap_d = (1, 3, 5, 6, 8, 9), [0, 1, 1, 0, 0, 0], b"\x6a\x03"
    delta = _shq_payload(resent, b"\x01\x01\x01\x01", bitmap=bitmap_d, cells=10, modes=modes)
    want = bytearray(base[:480])
    for i, (x, qs), m in zip(resent_at, resent, modes):
        want[48 * i:48 * i + 48] = b"".join(_shq_value(x, q, struct.unpack_from("<f", base, 48 * i + 4 * k)[0]
                                                       if m else None) for k, q in enumerate(qs))
    want = bytes(want) + b"\x0e\x01\xf1\x01"
    got = shq_decode_payload(delta, len(base), 10, False, base)
    if got != want:
        raise AssertionError("shq delta: cells %r differ from the values by hand" % (
            [i for i in range(10) if got[48 * i:48 * i + 48] != want[48 * i:48 * i + 48]],))
    ties = (struct.unpack_from("<12f", got, 3 * 48), struct.unpack_from("<12f", got, 5 * 48),
            struct.unpack_from("<12f", got, 6 * 48))
    if ties != ((-24.0, -24.0, -22.0, -20.0, -20.0, -20.0, -18.0, -16.0, -16.0, -16.0, -12.0, -14.0),
                (0.0, 0.0, 0.0, 4.0, 4.0, 4.0, 8.0, 8.0, 8.0, 8.0, 8.0, 24.0), (0.0,) * 12):
        raise AssertionError("shq delta's mode 1: (r + round(b 2^-x)) 2^x, ties to even, is not %r" % (ties,))
    # -- the same messages through a header, zstd and the session's delta bases (the ACKed tick's bytes)
    header = {"revision": 1, "tick": 1, "format": "fp32", "compression": "shq", "error_bound": 0.01,
              "keyframe": True, "grid": {"dims": [5, 2, 1], "origin": [0.0, 0.0, 0.0], "cell_size": 0.5},
              "cascades": [{"dims": [5, 2, 1], "origin": [0.0, 0.0, 0.0], "cell_size": 0.5, "cells": 10}],
              "units": LPV_UNITS, "raw_length": 480}
    through = "payloads only (no zstd decoder)"
    if zstd_decoder() is not None:
        c = Client(connect=False)
        vol = c._decode_volume(header, _zstd_raw_frame(_shq_payload(resent[:1] * 10)), ack=False)
        if vol.error_bound != 0.01 or vol.compression != "shq" or vol.raw != b"".join(
                _shq_value(0, 1) for _ in range(120)):
            raise AssertionError("shq keyframe through zstd: bound %r, compression %r, %r" % (
                vol.error_bound, vol.compression, vol.raw[:16]))
        c._remember(1, base[:480])
        vol = c._decode_volume(dict(header, tick=2, keyframe=False, base_tick=1),
                               _zstd_raw_frame(_shq_payload(resent, bitmap=bitmap_d, cells=10, modes=modes)),
                               ack=False)
        if vol.raw != want[:480] or vol.keyframe or vol.base_tick != 1:
            raise AssertionError("shq delta through zstd and the session's base differs from the values by hand")
        for what, att in (("a payload that is not zstd", _shq_payload(resent[:1] * 10)),
                          ("a zstd frame of more than the largest payload", _zstd_raw_frame(
                              _shq_payload(resent[:1] * 10) + bytes(10 ** 4)))):
            try:
                shq_decode(att, header)
                raise AssertionError("shq: %s was read" % what)
            except ProtocolError as e:
                if "zstd" not in str(e):
                    raise AssertionError("shq: %s refused without naming zstd: %s" % (what, e))
        through = "also through zstd (%s) and the session's delta bases" % zstd_decoder()
    # -- a seeded keyframe of 300 cells of every exponent and mantissa range, and a delta of it
    rnd = random.Random(16)
    cells = [(rnd.choice([-128, -127, 127, 126]) if i % 7 == 0 else rnd.randint(-128, 127),
              [rnd.randint(-32768, 32767) if k % 3 else rnd.randint(-3, 3) for k in range(12)]) for i in range(300)]
    seeded = shq_decode_payload(_shq_payload(cells), 300 * 48, 300, True)
    if seeded != b"".join(_shq_value(x, q) for x, qs in cells for q in qs):
        raise AssertionError("shq: the seeded keyframe differs from q x 2^x worked out with ** (numpy: %s)"
                             % (lpvd_volume._np is not None))
    # -- predicted keyframes (flag bit 1): the residuals worked out here with ** and floor, the decoder's
    # running sums must give back every q, through runs of one exponent, jumps of up to 15 and beyond, zero
    # cells and mantissas at both ends of 16 bits
    runs = [(rnd.choice([-128, 5, 5, 5, 6, 20, 21, 40]), [rnd.randint(-32768, 32767) if k % 2 else
                                                       rnd.randint(-40, 40) for k in range(12)]) for _ in range(300)]
    for plain in (cells, runs):
        residual, prev, prev_x = [], [0] * 12, -128
        for x, qs in plain:
            preds = []
            for pq in prev:
                if prev_x == -128 or x == -128 or abs(prev_x - x) > 15:
                    preds.append(0)
                    continue
                t = pq * 2.0 ** (prev_x - x)
                near = math.floor(t)
                preds.append(near + (1 if t - near > 0.5 or (t - near == 0.5 and near % 2) else 0))
            residual.append((x, [(q - d + 32768) % 65536 - 32768 for q, d in zip(qs, preds)]))
            prev, prev_x = qs, x
        got = shq_decode_payload(_shq_payload(residual, flags=3), 300 * 48, 300, True)
        if got != b"".join(_shq_value(x, q) for x, qs in plain for q in qs):
            raise AssertionError("shq: a predicted keyframe does not give back its cells (numpy: %s) in cells %r" % (
                lpvd_volume._np is not None, [i for i in range(300) if got[48 * i:48 * i + 48] != b"".join(
                    _shq_value(plain[i][0], q) for q in plain[i][1])][:10]))
    flags = [rnd.random() < 0.3 for _ in range(300)]
    bitmap = bytes(sum(1 << b for b in range(8) if 8 * i + b < 300 and flags[8 * i + b]) for i in range(38))
    seeded_delta = shq_decode_payload(_shq_payload([c for c, f in zip(cells, flags) if f], bitmap=bitmap, cells=300),
                                      300 * 48, 300, False, seeded[::-1])
    if seeded_delta != b"".join(seeded[48 * i:48 * i + 48] if f else seeded[::-1][48 * i:48 * i + 48]
                                for i, f in enumerate(flags)):
        raise AssertionError("shq: the seeded delta is not the cells sent over the base's")
    # -- a seeded delta of modes 0 and 1 against a finite base of every range (ties at every exponent,
    # subnormals, values near the largest binary32, so that some sums overflow to infinity, negative ones)
    based = []
    for i in range(300 * 12):
        x, pick = cells[i // 12][0], rnd.random()  # ties: the base's b x 2^-x at k + 1/2 in the cell's own steps
        based.append(rnd.choice([0.0, -0.0, 1e-45, -1e-45, 3.4e38, -3.4e38]) if pick < 0.05 else
                     (rnd.randint(-4096, 4096) + 0.5) * 2.0 ** x if pick < 0.5 else
                     rnd.randint(-2 ** 24, 2 ** 24) * 2.0 ** rnd.randint(-149, 103))
    finite = struct.pack("<%df" % len(based), *[max(-3.4e38, min(3.4e38, v)) for v in based])
    modes_s = [rnd.randint(0, 1) if x != -128 else 0 for x, _ in cells]
    sent_s = [(c, m) for c, m, f in zip(cells, modes_s, flags) if f]
    seeded_mixed = shq_decode_payload(_shq_payload([c for c, _ in sent_s], bitmap=bitmap, cells=300,
                                                   modes=[m for _, m in sent_s]), 300 * 48, 300, False, finite)
    want = []
    for i, ((x, qs), m, f) in enumerate(zip(cells, modes_s, flags)):
        want.append(b"".join(_shq_value(x, q, struct.unpack_from("<f", finite, 48 * i + 4 * k)[0] if m else None)
                             for k, q in enumerate(qs)) if f else finite[48 * i:48 * i + 48])
    if seeded_mixed != b"".join(want) or sum(m for m, f in zip(modes_s, flags) if f) < 20:
        raise AssertionError("shq: the seeded delta of modes 0 and 1 differs from (r + round(b 2^-x)) 2^x worked "
                             "out with ** (numpy: %s) in cells %r" % (lpvd_volume._np is not None, [
                                 i for i in range(300) if seeded_mixed[48 * i:48 * i + 48] != want[i]][:10]))
    # -- a delta with blocks (flag bit 2) of 12 cells: region A, cells 0-5 as 3 x 2 x 1, region B, cells 7-10
    # as 2 x 2 x 1, blocks of edge 2 (A: 2 blocks, B: 1); cells 6 and 11 outside both. Block 0 moves A's cells
    # 0, 1, 3, 4 by d 2^-1 but cell 4, black, stays black; block 1 (x = -128) leaves cells 2, 5; block 2
    # moves B's cells by d 2^0 from 2^24, where binary32's steps are 2: 2^24 + 1 and + 3 are ties (to even:
    # 2^24 and 2^24 + 4). Then cell 1 is re-sent as mode 1 (from the moved cell) and cell 9 as mode 0.
    bvals = [float(i - 5) + k / 16.0 for i in range(12) for k in range(12)]
    bvals[48:60] = [0.0] * 12  # cell 4 black
    bvals[84:132] = [2.0 ** 24] * 48  # cells 7-10
    bbase = struct.pack("<144f", *bvals) + b"\x05\x06\x07\x08"
    d0 = [1, -1, 2, -2, 3, -3, 32767, -32768, 0, 5, -5, 7]
    d2 = [1, 3, -1, -3, 2, 0, 5, 7, 1, 1, 3, 3]
    blocks_d = [(-1, d0), (-128, [9] * 12), (0, d2)]

    def blocks_section(regions, edge, blks):
        zz = [[2 * d if d >= 0 else -2 * d - 1 for d in ds] for _, ds in blks]
        return (struct.pack("<II", len(regions), edge) + b"".join(struct.pack("<QIII", *r) for r in regions)
                + struct.pack("<%db" % len(blks), *[x for x, _ in blks])
                + bytes(zz[t][k] & 0xFF for k in range(12) for t in range(len(blks)))
                + bytes(zz[t][k] >> 8 for k in range(12) for t in range(len(blks))))

    regions_ab = [(0, 3, 2, 1), (7, 2, 2, 1)]
    sent_b = [(-2, [4] * 12), (3, [1, -1] * 6)]

    def with_blocks(regions=regions_ab, edge=2, blks=blocks_d, flags=4):
        plain = _shq_payload(sent_b, b"\x01\x00\x00\x01", bitmap=b"\x02\x02", cells=12, modes=[1, 0], flags=flags)
        return plain[:32] + blocks_section(regions, edge, blks) + plain[32:]
    moved = list(bvals)
    for i in (0, 1, 3):  # block 0: + d 2^-1, exact here (values of steps 1/16 plus halves)
        for k in range(12):
            moved[12 * i + k] = struct.unpack("<f", struct.pack("<f", bvals[12 * i + k] + d0[k] * 0.5))[0]
    ties = {1: 2.0 ** 24, 3: 2.0 ** 24 + 4, -1: 2.0 ** 24 - 1, -3: 2.0 ** 24 - 3, 2: 2.0 ** 24 + 2, 0: 2.0 ** 24,
            5: 2.0 ** 24 + 4, 7: 2.0 ** 24 + 8}  # 2^24 + d by hand: steps of 2 above 2^24 (ties to even), 1 below
    for i in (7, 8, 9, 10):
        moved[12 * i:12 * i + 12] = [ties[d] for d in d2]
    want_b = bytearray(struct.pack("<144f", *moved))
    want_b[48:96] = b"".join(_shq_value(-2, 4, moved[12 + k]) for k in range(12))  # cell 1, mode 1 from the moved
    want_b[9 * 48:10 * 48] = b"".join(_shq_value(3, q) for q in [1, -1] * 6)
    want_b = bytes(want_b) + b"\x04\x06\x07\x09"
    got = shq_decode_payload(with_blocks(), len(bbase), 12, False, bbase)
    if got != want_b:
        raise AssertionError("shq delta with blocks: cells %r differ from the values by hand (numpy: %s)" % (
            [i for i in range(12) if got[48 * i:48 * i + 48] != want_b[48 * i:48 * i + 48]],
            lpvd_volume._np is not None))
    big = bytearray(bbase)
    big[0:4] = struct.pack("<f", 3.4028234663852886e38)  # cell 0 at the largest binary32, block 0 moves it up
    block_refusals = [
        ("blocks on a keyframe", lambda: shq_decode_payload(with_blocks(flags=5), len(bbase), 12, True), "flags"),
        ("no regions", lambda: shq_decode_payload(with_blocks(regions=[]), len(bbase), 12, False, bbase), "regions"),
        ("an edge 0", lambda: shq_decode_payload(with_blocks(edge=0), len(bbase), 12, False, bbase), "edge"),
        ("overlapping regions", lambda: shq_decode_payload(with_blocks(regions=[(0, 3, 2, 1), (5, 2, 2, 1)]),
                                                           len(bbase), 12, False, bbase), "in order"),
        ("a region past C", lambda: shq_decode_payload(with_blocks(regions=[(0, 3, 2, 1), (9, 2, 2, 1)]),
                                                       len(bbase), 12, False, bbase), "in order"),
        ("a block exponent of 101", lambda: shq_decode_payload(with_blocks(blks=[(101, d0)] + blocks_d[1:]),
                                                               len(bbase), 12, False, bbase), "exponent 101"),
        ("a sum past binary32", lambda: shq_decode_payload(with_blocks(blks=[(100, [32767] * 12)] + blocks_d[1:]),
                                                           len(bbase), 12, False, bytes(big)), "binary32"),
        ("a block too few", lambda: shq_decode_payload(with_blocks(blks=blocks_d[:2]), len(bbase), 12, False, bbase),
         "counts need"),
    ]
    # -- what a client MUST refuse (R5.16): header, magic, flags, counts, bit map, length, the blocks above
    k3 = key_cells[:3]
    refusals = block_refusals + [
        ("the magic", lambda: shq_decode_payload(_shq_payload(k3, magic=b"SHQ2"), 144, 3, True), "SHQ1"),
        ("an unknown flag", lambda: shq_decode_payload(_shq_payload(k3, flags=5), 144, 3, True), "flags"),
        ("a predicted delta", lambda: shq_decode_payload(_shq_payload(k3, flags=2), 144, 3, True), "flags"),
        ("a keyframe flag where the header has a delta",
         lambda: shq_decode_payload(_shq_payload(k3), 144, 3, False, bytes(144)), "keyframe"),
        ("a delta flag where the header has a keyframe",
         lambda: shq_decode_payload(_shq_payload(k3, bitmap=b"\x07", cells=3), 144, 3, True), "delta"),
        ("C other than the header's", lambda: shq_decode_payload(_shq_payload(k3, index), 152, 4, True), "cells"),
        ("X other than the header's", lambda: shq_decode_payload(_shq_payload(k3, index), 148, 3, True), "after"),
        ("S over C", lambda: shq_decode_payload(_shq_payload(k3, bitmap=b"\x03", counts=(2, 3, 0)), 96, 2, False,
                                                bytes(96)), "sent"),
        ("a keyframe's S under C", lambda: shq_decode_payload(_shq_payload(k3[:2], counts=(3, 2, 0)), 144, 3, True),
         "every cell"),
        ("a bit map of other than S bits",
         lambda: shq_decode_payload(_shq_payload(resent, bitmap=b"\x6a\x01", cells=10), 480, 10, False,
                                    base[:480]), "bit map"),
        ("a bit past C", lambda: shq_decode_payload(_shq_payload(resent, bitmap=b"\x6a\x06", cells=10), 480, 10,
                                                    False, base[:480]), "past"),
        ("a mode 2", lambda: shq_decode_payload(_shq_payload(resent, bitmap=bitmap_d, cells=10,
                                                             modes=[0, 1, 2, 0, 0, 0]), 480, 10, False,
                                                base[:480]), "mode 2"),
        ("a mode 255", lambda: shq_decode_payload(_shq_payload(resent, bitmap=bitmap_d, cells=10,
                                                               modes=[255, 1, 1, 0, 0, 0]), 480, 10, False,
                                                  base[:480]), "mode 255"),
        ("mode 1 with the zero exponent -128",
         lambda: shq_decode_payload(_shq_payload(resent, bitmap=bitmap_d, cells=10, modes=[0, 1, 1, 1, 0, 0]),
                                    480, 10, False, base[:480]), "zero exponent"),
        ("a delta without its modes", lambda: shq_decode_payload(_shq_payload(resent, bitmap=bitmap_d, cells=10)[
            :32 + 2 + 6] + _shq_payload(resent, bitmap=bitmap_d, cells=10)[32 + 2 + 12:], 480, 10, False,
                                                                 base[:480]), "counts need"),
        ("a byte more", lambda: shq_decode_payload(_shq_payload(k3) + b"\0", 144, 3, True), "counts need"),
        ("a byte less", lambda: shq_decode_payload(_shq_payload(k3)[:-1], 144, 3, True), "counts need"),
        ("a short head", lambda: shq_decode_payload(b"SHQ1" + bytes(20), 144, 3, True), "SHQ1"),
        ("a delta without its base", lambda: shq_decode_payload(delta, len(base), 10, False), "base"),
        ("a base of another length", lambda: shq_decode_payload(delta, len(base), 10, False, base[:-4]), "base"),
    ]
    for key, value, word in (("format", "fp16", "format"), ("error_bound", None, "error_bound"),
                             ("error_bound", SHQ_BOUND_MAX * 2, "error_bound"), ("error_bound", 0.0005, "error_bound"),
                             ("error_bound", "0.01", "error_bound"), ("error_bound", True, "error_bound"),
                             ("volume", {"values_per_cell": 13, "index": None}, "merged"),
                             ("volume", {"values_per_cell": 12, "index": None, "visibility": {}}, "visibility"),
                             ("raw_length", 481, "whole cells")):
        h = dict(header)
        if value is None:
            del h[key]
        else:
            h[key] = value
        refusals.append(("a header's %s %r" % (key, value), lambda h=h: shq_decode(b"", h), word))
    refusals.append(("a Volume of compression shq in fp16", lambda: Volume(dict(header, format="fp16"),
                                                                           bytes(240)), "fp32"))
    for what, decode, word in refusals:
        try:
            decode()
            raise AssertionError("shq: %s was read" % what)
        except ProtocolError as e:
            if word not in str(e):
                raise AssertionError("shq: %s refused without saying %r: %s" % (what, word, e))
    # -- D and M (R5.16) by hand: exact (1, 0, 0, 0) per channel has M = L0; held (1, 0.01, 0, 0) in red is
    # L1 x 0.01 off, over the bound 0.011 (L0 x 0.011 < L1 x 0.01) and within 0.012; a NaN counts as 0
    exact = [1.0, 0.0, 0.0, 0.0] * 3
    held = [1.0, 0.01, 0.0, 0.0] + [1.0, 0.0, 0.0, 0.0] * 2
    if not _close([shq_cell_magnitude(exact), shq_cell_magnitude([0, 3, 4, 0] + [0] * 8),
                   shq_cell_distance(held, exact)], [SH_LOBE0, 5 * SH_LOBE1, 0.01 * SH_LOBE1], 1e-12):
        raise AssertionError("shq: M and D differ from L0, 5 L1 and 0.01 L1")
    pack = struct.Struct("<12f").pack
    D, M = shq_distances(pack(*held) + pack(*[0.0] * 12), pack(*exact) + pack(float("nan"), *[0.0] * 11))
    over, cell = shq_bound_excess(pack(*held), pack(*exact), 0.011)
    within = shq_bound_excess(pack(*held), pack(*exact), 0.012)[0]
    if not (_close([float(v) for v in D] + [float(v) for v in M], [0.01 * SH_LOBE1, 0.0, SH_LOBE0, 0.0], 1e-6)
            and over > 0 and cell == 0 and within <= 0):
        raise AssertionError("shq: D %r, M %r, excess %r at cell %r over 0.011, %r within 0.012" % (
            list(D), list(M), over, cell, within))
    say("offline R5.16 (numpy: %s): a hand-made keyframe (zero, subnormal, infinite values) and delta decoded to the "
        "values by hand (mode 1: ties to even, negative), %s; seeded payloads of 300 cells as q x 2^x and (r + "
        "round(b 2^-x)) 2^x; a delta with blocks (binary32 sums, ties to even, black cells kept) by hand; %d "
        "malformed payloads and headers refused; D and M by hand" % (
            lpvd_volume._np is not None, through, len(refusals)))
    return seeded + seeded_delta + seeded_mixed + got


def offline_self_test(out=sys.stdout):
    """The client's checks that need no daemon (SPEC R5.15's decoding and
    lookup and R5.16's shq decoding on hand-made payloads), with numpy when
    it is importable and again without it (the two shq decoders must give
    the same bytes). Returns 0 on success, raises AssertionError."""
    import lpvd_volume

    def say(msg):
        out.write("self-test: %s\n" % msg)
        out.flush()
    np_ = lpvd_volume._np
    shq = []
    try:
        for np_now in ([np_, None] if np_ is not None else [None]):
            lpvd_volume._np = np_now
            _offline_probes(say)
            shq.append(_offline_shq(say))
    finally:
        lpvd_volume._np = np_
    if any(b != shq[0] for b in shq):
        raise AssertionError("shq: numpy's and the standard library's decoders give different bytes")
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


def _self_test_shq(c, centre, say):
    """SPEC R5.16: GET_VOLUME compression "shq" at two bounds and a delta
    stream of it (a light moved 1 cm, then nothing changed), each volume the
    client holds within the bound of GET_VOLUME fp32 of the newest tick."""
    codecs = c.volume_codecs or {}
    if "shq" not in codecs.get("compression", ()):
        raise AssertionError("HELLO's volume_codecs %r do not list \"shq\"" % (codecs,))
    if zstd_decoder() is None:
        say("compression shq: not decoded (neither the zstandard module nor libzstd is there)")
        return

    def within(held, bound, what, tick):
        exact = c.get_volume(format="fp32", compression="none")
        excess, cell = shq_bound_excess(held.raw, exact.raw, bound)
        if exact.tick != tick or excess > 0.0:
            raise AssertionError("shq %s (tick %s) vs the exact volume of tick %s (newest: %s): cell %s is %.3g past "
                                 "the bound %g" % (what, held.tick, exact.tick, tick, cell, excess, bound))
    for bound in (0.01, 0.1):
        vol = c.get_volume(compression="shq", error_bound=bound)
        if vol.error_bound != bound or vol.format != "fp32":
            raise AssertionError("GET_VOLUME shq: error_bound %r, format %r" % (vol.error_bound, vol.format))
        within(vol, bound, "GET_VOLUME at %g" % bound, vol.tick)
    c.subscribe("volume", compression="shq", delta=True, error_bound=0.01)
    kinds, held = [], None
    for step in range(3):
        if step == 1:  # a light moved 1 cm re-sends the cells it moved beyond the bound; step 2 changes nothing
            c.light_set("self-test", "point", 0.5, position=(centre[0] + 0.01, centre[1], centre[2]))
        t, vol = c.tick_volume()
        kinds.append("none" if vol is None else "keyframe" if vol.keyframe else "delta/%s" % vol.base_tick)
        held = vol if vol is not None else held
        if held is None:
            raise AssertionError("no VOLUME after the first TICK of an shq subscription")
        within(held, 0.01, "stream", t.get("tick"))
    c.unsubscribe("volume")
    if kinds[0] != "keyframe" or kinds[2] != "none":
        raise AssertionError("shq stream: %s, expected a keyframe first and nothing for a tick without a change"
                             % ", ".join(kinds))
    say("compression shq (%s) -> GET_VOLUME at 0.01 and 0.1 and the stream at 0.01 (%s) within the bound of "
        "GET_VOLUME fp32" % (zstd_decoder(), ", ".join(kinds)))


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
    _self_test_shq(c, centre, say)
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
    print("self-test passed (numpy: %s, zstandard: %s, zstd decoder: %s)" % (HAVE_NUMPY, HAVE_ZSTD, zstd_decoder()))
    return rc
