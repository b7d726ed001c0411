"""lpvd_selftest.py - the lpvd Python client's self-test and command line:
``python3 lpvd_client.py --self-test ADDRESS`` runs ``main``, a short
end-to-end check against a running daemon (exit status 0 on success).

Standard library only. One of the modules of the client; import
``lpvd_client``, which re-exports every name.

The protocol is protocol/SPEC.md; section numbers below refer to it.
"""

import json
import struct
import sys

from lpvd_protocol import HAVE_ZSTD, LpvdError, ProtocolError, default_address, plan_lines
from lpvd_session import Client
from lpvd_volume import HAVE_NUMPY, IV_UNITS, LayoutError, Volume


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


def self_test(address, token=None, glb=None, out=sys.stdout):
    """hello, (scene), tick, get_volume, query, stats, bye. Returns 0 on success."""
    def say(msg):
        out.write("self-test: %s\n" % msg)
        out.flush()

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
    args = ap.parse_args(argv)
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
    except (LpvdError, ProtocolError, OSError, AssertionError, ValueError) as e:
        sys.stderr.write("self-test FAILED: %s: %s\n" % (type(e).__name__, e))
        return 1
    print("self-test passed (numpy: %s, zstandard: %s)" % (HAVE_NUMPY, HAVE_ZSTD))
    return rc
