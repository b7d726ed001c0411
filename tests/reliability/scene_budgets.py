#!/usr/bin/env python3
"""scene_budgets.py - per-scene budgets and image defects (issue 14, items 2 and 7 in part).

An all-zero 8192x8192 PNG is ~70 KB (grey) yet decodes to 256 MiB of RGBA8: two
of them in one .glb used to be decoded (peak RSS up ~1 GB) and accepted. A PNG
whose header claims 16384x16384 (over --max-texture 8192), or garbage bytes
declared as a PNG, were accepted without their texture (R4.4 says a defect is
SCENE_INVALID, a size over a limit LIMIT).

Expected, on a daemon with the default limits:
  - two 8192x8192 images: LIMIT naming --max-scene-texels and the 134217728
    texels they need, decided from the headers: the daemon's peak RSS
    (VmHWM) rises by less than 200 MB (decoding one costs 256 MiB or more);
  - the 16384x16384 header: LIMIT naming --max-texture and "image 0";
  - garbage image bytes: SCENE_INVALID naming "image 0";
  - HELLO's limits carry max_scene_texels and max_scene_bytes.
And with --max-scene-bytes 1048576: a .glb with a 2 MiB buffer gets LIMIT naming
--max-scene-bytes; a small scene still loads.
"""

import json
import os
import struct
import sys
import zlib

from rel_common import harness, lc, hello


def png(width, height, rows=True):
    """A grey 8-bit PNG, all zero; rows=False: only the header and an empty IDAT (a lie)."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    z = zlib.compressobj(9)
    data = b""
    if rows:
        row = b"\0" * (width + 1)
        parts = [z.compress(row) for _ in range(height)]
        data = b"".join(parts) + z.flush()
    else:
        data = z.compress(b"\0") + z.flush()
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", data) + chunk(b"IEND", b"")


def textured_glb(images, pad=0):
    """One triangle using image 0 as its base colour; every image in the BIN chunk; pad: extra buffer bytes."""
    pos = b"".join(struct.pack("<3f", *v) for v in ((0, 0, 0), (1, 0, 0), (0, 1, 0)))
    uv = b"".join(struct.pack("<2f", *v) for v in ((0, 0), (1, 0), (0, 1)))
    binb = bytearray(pos + uv)
    views = [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 24}]
    imgs = []
    for im in images:
        while len(binb) % 4:
            binb += b"\0"
        views.append({"buffer": 0, "byteOffset": len(binb), "byteLength": len(im)})
        imgs.append({"bufferView": len(views) - 1, "mimeType": "image/png"})
        binb += im
    binb += b"\0" * pad
    while len(binb) % 4:
        binb += b"\0"
    gltf = {"asset": {"version": "2.0"}, "buffers": [{"byteLength": len(binb)}], "bufferViews": views,
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                           "min": [0, 0, 0], "max": [1, 1, 0]},
                          {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": 0}]}],
            "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0}
    if images:
        gltf.update({"images": imgs, "textures": [{"source": i} for i in range(len(imgs))],
                     "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]})
    else:
        gltf["materials"] = [{}]
    return lc.make_glb(gltf, bytes(binb))


def peak_kib(d):
    with open("/proc/%d/status" % d.pid) as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1])
    return 0


def expect(rep, c, glb, code, want, what):
    rid = c.send(lc.SCENE_LOAD, {}, glb)
    f = c.recv_reply(rid, timeout=120)
    msg = f.body.get("message", "") if f.type == lc.ERROR else ""
    good = f.type == lc.ERROR and f.body.get("code") == lc.ERROR_CODES[code] and all(w in msg for w in want)
    rep.check(good, "%s: %s naming %s" % (what, code, ", ".join(want)),
              json.dumps(f.body) if f.type == lc.ERROR else "type 0x%04x" % f.type)


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    args = ap.parse_args()
    rep = harness.Report("scene_budgets")
    lpvd = harness.find_lpvd(args.lpvd)
    d = harness.Daemon(lpvd)
    d.start()
    try:
        c = lc.Conn(("unix", d.unix), timeout=120)
        h = hello(c)
        lim = h.body.get("limits", {})
        rep.check(lim.get("max_scene_texels") == 64 << 20 and lim.get("max_scene_bytes") == 2 << 30,
                  "HELLO limits: max_scene_texels 67108864, max_scene_bytes 2147483648", json.dumps(lim))
        big = png(8192, 8192)
        d.reset_peak()
        before = peak_kib(d)
        expect(rep, c, textured_glb([big, big]), "LIMIT", ["--max-scene-texels", "134217728", "67108864"],
               "two all-zero 8192x8192 PNGs (%d KB each)" % (len(big) // 1024))
        rise_mb = (peak_kib(d) - before) / 1024.0
        rep.check(rise_mb < 200, "refused from the headers: peak RSS rose %.0f MB (< 200; a decode is >= 256)"
                  % rise_mb)
        expect(rep, c, textured_glb([png(16384, 16384, rows=False)]), "LIMIT",
               ["--max-texture", "image 0", "16384x16384", "8192"], "a PNG header claiming 16384x16384")
        expect(rep, c, textured_glb([b"\x89PNG\r\n\x1a\n" + b"garbage, not a PNG at all" * 4]), "SCENE_INVALID",
               ["image 0"], "garbage declared as a PNG")
        expect(rep, c, textured_glb([png(64, 64)[:60]]), "SCENE_INVALID", ["image 0"], "a truncated PNG")
        # fuzz_image's finding (docs/fuzzing.md): stb reserves 2 GiB of address space for this 90-byte PNG's
        # bogus zlib stored block and touches none of it
        seed = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "fuzz", "corpus_image",
                            "png-stored-block-2gib")
        with open(seed, "rb") as fh:
            bogus = fh.read()
        d.reset_peak()
        before = peak_kib(d)
        expect(rep, c, textured_glb([bogus]), "SCENE_INVALID", ["image 0"], "a 1x8 PNG whose zlib block claims 2 GiB")
        rise_mb = (peak_kib(d) - before) / 1024.0
        bound = 512 if harness.is_asan(lpvd) else 64  # ASan writes shadow for the freed 2 GiB: 256 MB
        rep.check(rise_mb < bound, "and the peak RSS rose %.1f MB (< %d)" % (rise_mb, bound))
        ok = c.request(lc.SCENE_LOAD, {}, textured_glb([png(64, 64)]), timeout=120)
        rep.check(ok.type == (lc.SCENE_LOAD | lc.REPLY), "a good 64x64 PNG still loads", json.dumps(ok.body))
    finally:
        d.kill()
    d = harness.Daemon(lpvd, optional=[("--max-scene-bytes", "1048576")])
    d.start()
    try:
        c = lc.Conn(("unix", d.unix), timeout=120)
        hello(c)
        expect(rep, c, textured_glb([], pad=2 << 20), "LIMIT", ["--max-scene-bytes", "1048576"],
               "a 2 MiB buffer with --max-scene-bytes 1048576")
        ok = c.request(lc.SCENE_LOAD, {}, textured_glb([png(64, 64)]), timeout=120)
        rep.check(ok.type == (lc.SCENE_LOAD | lc.REPLY), "a small scene still loads under that budget",
                  json.dumps(ok.body))
        return rep.finish(d)
    finally:
        d.kill()


if __name__ == "__main__":
    sys.exit(main())
