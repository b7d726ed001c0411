"""conf_scenes.py - conformance cases: scene loading: paths under the scene root, glb
attachments, images and texel budgets, defective files (R4.3 - R4.5b)."""

import os
import shutil
import struct
import tempfile

from conf_wire import GET_VOLUME, SCENE_LOAD, TICK
from conf_payloads import SMALL_CONFIG, box_scene_glb, f32_list, make_glb
from conf_core import Fail, Skip, case, check, expect_error, expect_reply


# ---------------------------------------------------------------------------
# Cases: scenes


@case("R4.3", "scene paths escaping the root or absolute get PATH_REFUSED")
def c_path_refused(ctx):
    c = ctx.session()
    paths = ["../x.glb", "/etc/passwd", "a/../../x.glb", "..", "/tmp/../etc/hostname", "./../../x.glb"]
    for p in paths:
        rid = c.send(SCENE_LOAD, {"path": p})
        f = c.recv_reply(rid, timeout=ctx.tick_timeout)
        try:
            expect_error(f, "PATH_REFUSED", rid)
        except Fail as e:
            raise Fail("path %r: %s" % (p, e))
    ctx.ping(c)
    return "%d paths refused" % len(paths)


@case("R4.3b", "an empty scene path gets BAD_FIELD saying it is empty")
def c_path_empty(ctx):
    c = ctx.session()
    rid = c.send(SCENE_LOAD, {"path": ""})
    f = c.recv_reply(rid, timeout=ctx.tick_timeout)
    expect_error(f, "BAD_FIELD", rid, field="empty")
    ctx.ping(c)
    return "\"\" refused as empty"


@case("R4.3", "a symlink inside the root pointing outside gets PATH_REFUSED; a file inside loads",
      needs=("scene_root",))
def c_path_symlink(ctx):
    root = ctx.args.scene_root
    if not root:
        raise Skip("no --scene-root given")
    outside = tempfile.mkdtemp(prefix="lpvd-conf-outside-")
    try:
        target = os.path.join(outside, "secret.glb")
        with open(target, "wb") as fh:
            fh.write(box_scene_glb())
        link = os.path.join(root, "conf-link-%d.glb" % os.getpid())
        dlink = os.path.join(root, "conf-dirlink-%d" % os.getpid())
        inside = os.path.join(root, "conf-box-%d.glb" % os.getpid())
        with open(inside, "wb") as fh:
            fh.write(box_scene_glb())
        for p in (link, dlink):
            if os.path.lexists(p):
                os.unlink(p)
        os.symlink(target, link)
        os.symlink(outside, dlink)
        try:
            c = ctx.session()
            for p in (os.path.basename(link), os.path.basename(dlink) + "/secret.glb"):
                rid = c.send(SCENE_LOAD, {"path": p})
                f = c.recv_reply(rid, timeout=ctx.tick_timeout)
                try:
                    expect_error(f, "PATH_REFUSED", rid)
                except Fail as e:
                    raise Fail("symlink %r: %s" % (p, e))
            rid = c.send(SCENE_LOAD, {"path": os.path.basename(inside)})
            f = c.recv_reply(rid, timeout=ctx.tick_timeout)
            expect_reply(f, SCENE_LOAD, rid, "SCENE_LOAD of a file inside the root")
            sc = f.body.get("scene", {})
            check(isinstance(f.body.get("revision"), int), "SCENE_LOAD reply without revision")
            check(sc.get("triangles") == 10, "scene.triangles %r, expected 10" % sc.get("triangles"))
            check(isinstance(sc.get("bounds"), list) and len(sc["bounds"]) == 6, "scene.bounds %r"
                  % sc.get("bounds"))
        finally:
            for p in (link, dlink, inside):
                if os.path.lexists(p):
                    os.unlink(p)
    finally:
        shutil.rmtree(outside, ignore_errors=True)
    return "2 symlinks refused, inside file loaded"


@case("R4.4", "SCENE_LOAD with a glb attachment: reply describes the scene")
def c_scene_attachment(ctx):
    c = ctx.session()
    f = expect_reply(c.request(SCENE_LOAD, {}, box_scene_glb(), timeout=ctx.tick_timeout), SCENE_LOAD)
    sc = f.body.get("scene")
    check(isinstance(sc, dict), "reply has no \"scene\" object: %r" % f.body)
    check(isinstance(f.body.get("revision"), int), "reply has no integer revision")
    check(sc.get("triangles") == 10, "triangles %r, expected 10" % sc.get("triangles"))
    check(sc.get("materials") == 3, "materials %r, expected 3" % sc.get("materials"))
    check(sc.get("lights") == 1, "lights %r, expected 1" % sc.get("lights"))
    # the glb has no camera: the server adds its default camera (docs/scenes.md, "Defaults")
    check(sc.get("cameras") == 1, "cameras %r, expected 1 (the default camera)" % sc.get("cameras"))
    check(sc.get("default_camera") is True, "default_camera %r, expected true" % sc.get("default_camera"))
    check(sc.get("default_light") is False, "default_light %r, expected false" % sc.get("default_light"))
    b = sc.get("bounds")
    check(isinstance(b, list) and len(b) == 6, "bounds %r" % b)
    want = [-1, 0, -1, 1, 2, 1]
    check(all(abs(x - y) < 1e-4 for x, y in zip(b, want)), "bounds %r, expected %r" % (b, want))
    return "10 triangles, 3 materials, 1 light, the default camera"


def grey_png(width, height, rows=True):
    """An all-zero 8-bit grey PNG; rows=False: its header and an empty IDAT only (a header that lies)."""
    import zlib

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    z = zlib.compressobj(9)
    row = b"\0" * (width + 1)
    data = b"".join(z.compress(row) for _ in range(height if rows else 0)) + z.flush()
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)) +
            chunk(b"IDAT", data) + chunk(b"IEND", b""))


def textured_triangle_glb(images):
    """One triangle whose material uses image 0; every image (PNG bytes) in the BIN chunk."""
    binb = bytearray(struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<6f", 0, 0, 1, 0, 0, 1))
    views = [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 24}]
    for im in images:
        views.append({"buffer": 0, "byteOffset": len(binb), "byteLength": len(im)})
        binb += im + b"\0" * (-len(im) % 4)
    gltf = {"asset": {"version": "2.0"}, "buffers": [{"byteLength": len(binb)}], "bufferViews": views,
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                           "min": [0, 0, 0], "max": [1, 1, 0]},
                          {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}],
            "images": [{"bufferView": 2 + i, "mimeType": "image/png"} for i in range(len(images))],
            "textures": [{"source": i} for i in range(len(images))],
            "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": 0}]}],
            "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0}
    return make_glb(gltf, bytes(binb))


@case("R4.5b", "an image that cannot be decoded, or whose header is over max_texture, refuses the scene")
def c_scene_bad_images(ctx):
    c = ctx.session()
    lim = (ctx.limits or {}).get("max_texture")
    cases = [("garbage declared as a PNG", textured_triangle_glb([b"\x89PNG\r\n\x1a\n" + b"not a png" * 8]),
              "SCENE_INVALID"),
             ("a truncated PNG", textured_triangle_glb([grey_png(32, 32)[:50]]), "SCENE_INVALID")]
    if isinstance(lim, int) and lim < (1 << 24):
        cases.append(("a PNG header claiming %dx%d" % (lim + 1, lim + 1),
                      textured_triangle_glb([grey_png(lim + 1, lim + 1, rows=False)]), "LIMIT"))
    for what, glb, code in cases:
        rid = c.send(SCENE_LOAD, {}, glb)
        f = c.recv_reply(rid, timeout=ctx.tick_timeout)
        try:
            expect_error(f, code, rid, field="image 0")
        except Fail as e:
            raise Fail("%s: %s" % (what, e))
    expect_reply(c.request(SCENE_LOAD, {}, textured_triangle_glb([grey_png(16, 16)]), timeout=ctx.tick_timeout),
                 SCENE_LOAD, what="a good 16x16 PNG")
    return "%d bad images refused, a good one loads" % len(cases)


@case("R4.5a", "images over max_scene_texels together get LIMIT before decoding")
def c_scene_texel_budget(ctx):
    c = ctx.session()
    lim = ctx.limits or {}
    budget, side = lim.get("max_scene_texels"), lim.get("max_texture")
    if not isinstance(budget, int) or not isinstance(side, int):
        raise Skip("HELLO limits advertise no max_scene_texels / max_texture")
    side = min(side, 8192)
    n = budget // (side * side) + 1
    if n > 16:
        raise Skip("max_scene_texels %d needs more than 16 images of %d^2" % (budget, side))
    im = grey_png(side, side)
    rid = c.send(SCENE_LOAD, {}, textured_triangle_glb([im] * n))
    f = c.recv_reply(rid, timeout=ctx.tick_timeout)
    expect_error(f, "LIMIT", rid, field="max-scene-texels")
    check(str(n * side * side) in f.body["message"], "the message %r does not say the %d texels needed"
          % (f.body["message"], n * side * side))
    ctx.ping(c)
    return "%d images of %d^2 (%d KB each) refused" % (n, side, len(im) // 1024)


@case("R4.4", "glb files that lie about their sizes get SCENE_INVALID; the session keeps its scene")
def c_scene_invalid(ctx):
    c, cfg, t0 = ctx.scene_session()
    v0 = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    good = box_scene_glb()
    js_len = struct.unpack_from("<I", good, 12)[0]
    bad = [
        ("total length larger than the file", good[:8] + struct.pack("<I", len(good) + 4096) + good[12:]),
        ("total length smaller than the file", good[:8] + struct.pack("<I", len(good) - 40) + good[12:]),
        ("JSON chunk length past the end", good[:12] + struct.pack("<I", len(good) * 4) + good[16:]),
        ("BIN chunk length past the end", good[:20 + js_len] + struct.pack("<I", 1 << 30) + good[24 + js_len:]),
        ("truncated file", good[:len(good) // 2]),
        ("wrong magic", b"glTX" + good[4:]),
        ("empty attachment", b""),
        ("12 bytes", good[:12]),
        ("external URI", box_scene_glb(uri="../../../../etc/passwd")),
        ("external URI (http)", box_scene_glb(uri="http://example.invalid/x.bin")),
    ]
    for what, data in bad:
        rid = c.send(SCENE_LOAD, {}, data)
        f = c.recv_reply(rid, timeout=ctx.tick_timeout)
        if what == "empty attachment" and f.err_name in ("BAD_FIELD", "NOT_READY"):
            continue  # {} with no attachment is not a glb load at all: BAD_FIELD is fine too
        try:
            expect_error(f, "SCENE_INVALID", rid)
        except Fail as e:
            raise Fail("%s: %s" % (what, e))
    t1 = expect_reply(c.request(TICK, {}, timeout=ctx.tick_timeout), TICK, what="TICK after refused scenes")
    v = expect_reply(c.request(GET_VOLUME, {"format": "fp32", "compression": "none"}), GET_VOLUME)
    dims = v.body.get("grid", {}).get("dims")
    check(dims == SMALL_CONFIG["grid"], "volume dims %r after refused scenes, expected %r" % (dims,
                                                                                          SMALL_CONFIG["grid"]))
    check(any(x != 0.0 for x in f32_list(v.att)[0::4]), "the kept scene's volume is all zero")
    check(v.att == v0.att, "the volume after the refused loads differs from the one before them "
          "(the session did not keep its previous scene)")
    return "%d defective files refused, session still ticks with the same volume" % len(bad)
