#!/usr/bin/env python3
"""gltf_features.py - lpvd's full frame against the path tracer's on files that use the glTF features
issue 32 added (docs/render.md "Scenes", docs/scenes.md): a skinned and a morphed file posed at a time, a file
whose labels glow through an emissive texture (and whose partial coating is alphaMode BLEND), a textured
box, a vertex-coloured room this script writes (no file of Debian's corpus carries COLOR_0), the
accuracy set's translucent panes (scenes/glass.glb, alphaMode BLEND), and the files docs/render.md's feature
table names for triangles and node transforms, Draco, texture transforms, cameras, a double-sided emitter
and lines.

For each: `lpvd render FILE [--time T] --size WxH -o lpvd.exr` and `lpvd-reference FILE [--time T] --full
--bounces converged --spp N --size WxH -o ref.exr` (the same camera: both choose it alike), then over the
pixels the reference sees: rel. RMSE = sqrt(mean((lpvd - ref)^2)) / mean(ref) and rel. bias =
(mean(lpvd) - mean(ref)) / mean(ref), on the three channels' sum. Prints a Markdown table and writes
the images (PNG previews side by side) under --out.

    /usr/bin/python3 bench/gltf_features.py --build build --out /tmp/gltf-features
"""

import argparse
import os
import struct
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio

MODELS = os.environ.get("LPVD_ASSIMP_MODELS", "/usr/share/assimp/models") + "/glTF2"
REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def vertex_coloured_room(path):
    """A 4 m room (floor, back and side walls, open front and top) whose floor's corners are red, green,
    blue and white (COLOR_0, VEC4 float) and whose walls are white, lit by a point light at its middle."""
    quads = [  # corners counter-clockwise seen from inside, colour per corner
        ([(-2, 0, -2), (-2, 0, 2), (2, 0, 2), (2, 0, -2)], [(1, 0, 0, 1), (0, 1, 0, 1), (0, 0, 1, 1), (1, 1, 1, 1)]),
        ([(-2, 0, -2), (2, 0, -2), (2, 3, -2), (-2, 3, -2)], [(1, 1, 1, 1)] * 4),
        ([(-2, 0, 2), (-2, 0, -2), (-2, 3, -2), (-2, 3, 2)], [(1, 1, 1, 1)] * 4),
        ([(2, 0, -2), (2, 0, 2), (2, 3, 2), (2, 3, -2)], [(1, 1, 1, 1)] * 4),
    ]
    pos, col, idx = [], [], []
    for c, k in quads:
        b = len(pos)
        pos += c
        col += k
        idx += [b, b + 1, b + 2, b, b + 2, b + 3]
    pb = b"".join(struct.pack("<3f", *p) for p in pos)
    cb = b"".join(struct.pack("<4f", *c) for c in col)
    ib = struct.pack("<%dH" % len(idx), *idx)
    ib += b"\0" * (-len(ib) % 4)
    binb = pb + cb + ib
    doc = {
        "asset": {"version": "2.0", "generator": "bench/gltf_features.py"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 3000}]}},
        "buffers": [{"byteLength": len(binb)}],
        "bufferViews": [{"buffer": 0, "byteLength": len(pb)},
                        {"buffer": 0, "byteOffset": len(pb), "byteLength": len(cb)},
                        {"buffer": 0, "byteOffset": len(pb) + len(cb), "byteLength": len(ib)}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(pos), "type": "VEC3",
                       "min": [-2, 0, -2], "max": [2, 3, 2]},
                      {"bufferView": 1, "componentType": 5126, "count": len(col), "type": "VEC4"},
                      {"bufferView": 2, "componentType": 5123, "count": len(idx), "type": "SCALAR"}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0},
                       "doubleSided": True}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "COLOR_0": 1}, "indices": 2, "material": 0}]}],
        "nodes": [{"mesh": 0}, {"translation": [0, 2.2, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.05}}],
        "scenes": [{"nodes": [0, 1, 2]}], "scene": 0,
    }
    doc["nodes"].append({"camera": 0, "translation": [0, 2.4, 5.5], "rotation": [-0.2164, 0, 0, 0.9763]})
    import json
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    out = struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(binb), 0x004E4942) + binb
    with open(path, "wb") as f:
        f.write(struct.pack("<4sII", b"glTF", 2, 12 + len(out)) + out)


def read(path):
    return oiio.ImageBuf(path).get_pixels(oiio.FLOAT)


def preview(img, ev):
    x = np.clip(img[..., :3] * 683.0 * 2.0 ** ev, 0, None)
    x = x / (1.0 + x)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--out", default="gltf-features-out")
    ap.add_argument("--size", default="128x128")
    ap.add_argument("--spp", type=int, default=256)
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    room = os.path.join(a.out, "vertex-coloured-room.glb")
    vertex_coloured_room(room)
    cases = [
        ("skinned (simple_skin, t = 1 s)", MODELS + "/simple_skin/simple_skin.gltf", ["--time", "1"]),
        ("morphed (AnimatedMorphCube, t = 1.5 s)",
         MODELS + "/glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf", ["--time", "1.5"]),
        ("emissive texture (ClearCoatTest's labels)", MODELS + "/ClearCoat-glTF/ClearCoatTest.gltf", []),
        ("base colour texture (BoxTextured)", MODELS + "/BoxTextured-glTF/BoxTextured.gltf", []),
        ("vertex colours (COLOR_0, this script's room)", room, []),
        ("translucent panes (BLEND, scenes/glass.glb)", os.path.join(REPO, "scenes", "glass.glb"), []),
        ("triangles, node transforms (2CylinderEngine)", MODELS + "/2CylinderEngine-glTF-Binary/2CylinderEngine.glb",
         []),
        ("Draco (draco/2CylinderEngine)", MODELS + "/draco/2CylinderEngine.gltf", []),
        ("texture transforms (TextureTransformTest)", MODELS + "/textureTransform/TextureTransformTest.gltf", []),
        ("cameras (Cameras)", MODELS + "/cameras/Cameras.gltf", []),
        ("double-sided emitter (scenes/panel-room.glb)", os.path.join(REPO, "scenes", "panel-room.glb"), []),
        ("lines (Mesh_PrimitiveMode_01; the reference sees none)",
         MODELS + "/glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_01.gltf", []),
    ]
    lpvd = os.path.join(a.build, "server", "lpvd")
    ref = os.path.join(a.build, "reference", "lpvd-reference")
    print("| file | rel. RMSE | rel. bias |")
    print("| --- | ---: | ---: |")
    for i, (name, path, extra) in enumerate(cases):
        mine, theirs = os.path.join(a.out, "%d-lpvd.exr" % i), os.path.join(a.out, "%d-ref.exr" % i)
        subprocess.run([lpvd, "render", path, "--size", a.size, "-o", mine] + extra, check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        subprocess.run([ref, path, "--full", "--bounces", "converged", "--spp", str(a.spp), "--size", a.size,
                        "-o", theirs] + extra, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        x, r = read(mine), read(theirs)
        seen = r[..., 3] > 0.5
        if not seen.any():  # nothing with a surface (lines): no figure, the picture exposed on lpvd's
            print("| %s | n/a | n/a |" % name)
            shown = x[..., :3].sum(axis=2)[x[..., 3] > 0.5]
        else:
            xs, rs = x[..., :3].sum(axis=2)[seen], r[..., :3].sum(axis=2)[seen]
            m = rs.mean()
            rmse = float(np.sqrt(np.mean((xs - rs) ** 2)) / m)
            bias = float((xs.mean() - m) / m)
            print("| %s | %.3f | %+.3f |" % (name, rmse, bias))
            shown = r[..., :3].sum(axis=2)[seen]
        ev = -float(np.log2(max(np.percentile(shown, 90) * 683.0 / 3.0, 1e-12))) if shown.size else 0.0
        row = np.concatenate([preview(x, ev), preview(r, ev)], axis=1)
        o = oiio.ImageBuf(oiio.ImageSpec(row.shape[1], row.shape[0], 3, oiio.UINT8))
        o.set_pixels(oiio.ROI(), row.astype(np.float32))
        o.write(os.path.join(a.out, "%d-side-by-side.png" % i))
    return 0


if __name__ == "__main__":
    sys.exit(main())
