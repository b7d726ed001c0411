"""conf_payloads.py - payloads the conformance cases send and read: volume and frame bytes
(fp32/fp16 lists, XOR deltas, zstd frame headers), the glb scenes and PNG textures built here
(box_scene_glb, triangles_glb, textured_glb, ...) and SMALL_CONFIG, the cheap default CONFIG."""

import json
import math
import shutil
import struct
import subprocess
import zlib

from conf_wire import ZSTD_MAGIC


# ---------------------------------------------------------------------------
# Payload helpers


def f32_list(data):
    return struct.unpack("<%df" % (len(data) // 4), data)


def f16_list(data):
    return struct.unpack("<%de" % (len(data) // 2), data)


def xor_bytes(a, b):
    n = len(a)
    return (int.from_bytes(a, "little") ^ int.from_bytes(b, "little")).to_bytes(n, "little")


def zstd_frame_content_size(data):
    """(ok, content_size or None, why) from a zstd frame header (RFC 8878 section 3.1.1)."""
    if len(data) < 6 or data[:4] != ZSTD_MAGIC:
        return False, None, "no zstd frame magic 0xFD2FB528 (first bytes %s)" % data[:4].hex()
    fhd = data[4]
    fcs_flag, single, dict_flag = fhd >> 6, (fhd >> 5) & 1, fhd & 3
    if fhd & 0x08:
        return False, None, "zstd frame header descriptor has the reserved bit set"
    pos = 5 + (0 if single else 1) + (0, 1, 2, 4)[dict_flag]
    size = (1 if single else 0, 2, 4, 8)[fcs_flag]
    if size == 0:
        return True, None, "frame content size not stored"
    if len(data) < pos + size:
        return False, None, "zstd frame header truncated"
    v = int.from_bytes(data[pos:pos + size], "little")
    if size == 2:
        v += 256
    return True, v, ""


def zstd_decompress_cli(data):
    """Decompresses with the zstd command-line tool when it is installed, else None."""
    exe = shutil.which("zstd")
    if not exe:
        return None
    p = subprocess.run([exe, "-d", "-c", "-q"], input=data, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       timeout=60)
    if p.returncode != 0:
        raise ValueError("zstd -d failed: %s" % p.stderr.decode(errors="replace").strip())
    return p.stdout


def make_glb(json_obj, bin_data=b"", *, lie_total=None, lie_json_len=None, magic=b"glTF"):
    """A .glb container (version 2). lie_*: header fields that do not match the content."""
    js = json.dumps(json_obj, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    out = struct.pack("<II", len(js) if lie_json_len is None else lie_json_len, 0x4E4F534A) + js
    if bin_data:
        b = bin_data + b"\0" * (-len(bin_data) % 4)
        out += struct.pack("<II", len(b), 0x004E4942) + b
    total = 12 + len(out)
    return struct.pack("<4sII", magic, 2, total if lie_total is None else lie_total) + out


def box_scene_glb(light_intensity=500.0, light_pos=(0.0, 1.6, 0.0), with_light=True, uri=None, animated=False,
                  block=None):
    """A small open-front box, 2 m wide (x, z in [-1, 1], y in [0, 2]): white floor, ceiling and back wall,
    red left wall, green right wall, and a KHR_lights_punctual point light inside. 10 triangles.
    uri: an external buffer URI instead of the BIN chunk (for the refusal cases).
    animated: an animation "Swing" turns the box 90 degrees about y over its 1 s (R4.4c).
    block: ((x0, y0, z0), (x1, y1, z1)), a closed white block between those corners, faces outward (12
    triangles more)."""
    quads = {
        "white": [
            [(-1, 0, -1), (1, 0, -1), (1, 0, 1), (-1, 0, 1)],      # floor, facing +y
            [(-1, 2, 1), (1, 2, 1), (1, 2, -1), (-1, 2, -1)],      # ceiling, facing -y
            [(-1, 0, -1), (-1, 2, -1), (1, 2, -1), (1, 0, -1)],    # back wall, facing +z
        ],
        "red": [[(-1, 0, 1), (-1, 2, 1), (-1, 2, -1), (-1, 0, -1)]],   # left wall, facing +x
        "green": [[(1, 0, -1), (1, 2, -1), (1, 2, 1), (1, 0, 1)]],     # right wall, facing -x
    }
    if block is not None:
        (x0, y0, z0), (x1, y1, z1) = block
        quads["white"] += [  # counter-clockwise seen from outside
            [(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)][::-1],   # bottom, facing -y
            [(x0, y1, z1), (x1, y1, z1), (x1, y1, z0), (x0, y1, z0)][::-1],   # top, facing +y
            [(x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)][::-1],   # back, facing -z
            [(x0, y0, z1), (x0, y1, z1), (x1, y1, z1), (x1, y0, z1)],         # front, facing +z
            [(x0, y0, z1), (x0, y1, z1), (x0, y1, z0), (x0, y0, z0)][::-1],   # left, facing -x
            [(x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)][::-1],   # right, facing +x
        ]
    colours = {"white": [0.8, 0.8, 0.8, 1], "red": [0.8, 0.1, 0.1, 1], "green": [0.1, 0.8, 0.1, 1]}
    binb = bytearray()
    accessors, views, prims, materials = [], [], [], []
    for mi, (name, qs) in enumerate(quads.items()):
        materials.append({"name": name, "pbrMetallicRoughness": {"baseColorFactor": colours[name],
                                                                 "metallicFactor": 0, "roughnessFactor": 1}})
        pos, idx = [], []
        for q in qs:
            base = len(pos)
            pos += q
            # counter-clockwise seen from the side each quad faces (glTF's front;
            # the materials are single-sided, so a viewer culls the other side)
            idx += [base, base + 2, base + 1, base, base + 3, base + 2]
        pb = b"".join(struct.pack("<3f", *p) for p in pos)
        ib = struct.pack("<%dH" % len(idx), *idx)
        ib += b"\0" * (-len(ib) % 4)
        views.append({"buffer": 0, "byteOffset": len(binb), "byteLength": len(pb)})
        binb += pb
        views.append({"buffer": 0, "byteOffset": len(binb), "byteLength": len(ib)})
        binb += ib
        mins = [min(p[i] for p in pos) for i in range(3)]
        maxs = [max(p[i] for p in pos) for i in range(3)]
        accessors.append({"bufferView": len(views) - 2, "componentType": 5126, "count": len(pos), "type": "VEC3",
                          "min": mins, "max": maxs})
        accessors.append({"bufferView": len(views) - 1, "componentType": 5123, "count": len(idx), "type": "SCALAR"})
        prims.append({"attributes": {"POSITION": len(accessors) - 2}, "indices": len(accessors) - 1,
                      "material": mi})
    animations = []
    if animated:
        keys = struct.pack("<2f", 0, 1) + struct.pack("<8f", 0, 0, 0, 1, 0, 0.70710678, 0, 0.70710678)
        views.append({"buffer": 0, "byteOffset": len(binb), "byteLength": 8})
        views.append({"buffer": 0, "byteOffset": len(binb) + 8, "byteLength": 32})
        binb += keys
        accessors.append({"bufferView": len(views) - 2, "componentType": 5126, "count": 2, "type": "SCALAR",
                          "min": [0], "max": [1]})
        accessors.append({"bufferView": len(views) - 1, "componentType": 5126, "count": 2, "type": "VEC4"})
        animations = [{"name": "Swing", "channels": [{"sampler": 0, "target": {"node": 0, "path": "rotation"}}],
                       "samplers": [{"input": len(accessors) - 2, "output": len(accessors) - 1}]}]
    buf = {"byteLength": len(binb)}
    if uri is not None:
        buf["uri"] = uri
    doc = {
        "asset": {"version": "2.0", "generator": "lpvd_conformance"},
        "scene": 0,
        "scenes": [{"nodes": [0] + ([1] if with_light else [])}],
        "nodes": [{"mesh": 0, "name": "box"}],
        "meshes": [{"primitives": prims}],
        "materials": materials,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [buf],
    }
    if animations:
        doc["animations"] = animations
    if with_light:
        doc["extensionsUsed"] = ["KHR_lights_punctual"]
        doc["extensions"] = {"KHR_lights_punctual": {"lights": [
            {"type": "point", "color": [1, 1, 1], "intensity": light_intensity}]}}
        doc["nodes"].append({"name": "lamp", "translation": list(light_pos),
                             "extensions": {"KHR_lights_punctual": {"light": 0}}})
    return make_glb(doc, b"" if uri is not None else bytes(binb))


def triangles_glb(n):
    """n small non-indexed triangles on the floor of a 2 m square (for the triangle limit, R4.5)."""
    side = int(math.ceil(math.sqrt(n)))
    step = 2.0 / side
    out = bytearray()
    for i in range(n):
        x = -1.0 + (i % side) * step
        z = -1.0 + (i // side) * step
        out += struct.pack("<9f", x, 0.0, z, x, 0.0, z + step, x + step, 0.0, z)
    doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
           "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
           "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3 * n, "type": "VEC3",
                          "min": [-1.0, 0.0, -1.0], "max": [1.0 + step, 0.0, 1.0 + step]}],
           "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(out)}],
           "buffers": [{"byteLength": len(out)}]}
    return make_glb(doc, bytes(out))


def png_bytes(width, height, rgb=(200, 180, 160)):
    row = b"\0" + bytes(rgb) * width
    raw = zlib.compress(row * height, 9)

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", raw) + chunk(b"IEND", b""))


def textured_glb(tex_w, tex_h):
    """One textured quad whose base colour texture is a tex_w x tex_h PNG (for the texture limit, R4.5)."""
    pos = struct.pack("<12f", -1, 0, -1, 1, 0, -1, 1, 0, 1, -1, 0, 1)
    uv = struct.pack("<8f", 0, 0, 1, 0, 1, 1, 0, 1)
    idx = struct.pack("<6H", 0, 2, 1, 0, 3, 2) + b"\0\0"
    img = png_bytes(tex_w, tex_h)
    img += b"\0" * (-len(img) % 4)
    binb = pos + uv + idx + img
    o_uv, o_idx, o_img = len(pos), len(pos) + len(uv), len(pos) + len(uv) + len(idx)
    doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
           "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2,
                                       "material": 0}]}],
           "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
           "textures": [{"source": 0}],
           "images": [{"bufferView": 3, "mimeType": "image/png"}],
           "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                          "min": [-1, 0, -1], "max": [1, 0, 1]},
                         {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
                         {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}],
           "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(pos)},
                           {"buffer": 0, "byteOffset": o_uv, "byteLength": len(uv)},
                           {"buffer": 0, "byteOffset": o_idx, "byteLength": 12},
                           {"buffer": 0, "byteOffset": o_img, "byteLength": len(png_bytes(tex_w, tex_h))}],
           "buffers": [{"byteLength": len(binb)}]}
    return make_glb(doc, binb)


# Settings that keep a tick cheap on llvmpipe.
# normal_bins and far_field off: the volume is then exactly what the server's
# QUERY_IRRADIANCE reads with R5.7's lookup (with bins on the volume is the
# bins' sum, which the server reads per bin; with the far field the server sums
# its levels), so the R5.1/R4.7 cross-check can hold to float rounding.
# technique lpv named: the volume cases read the LPV's grid (its dims are the
# configured grid, R5.1) and R5.7's lookup; lpvd's default is "auto" since
# issue 30, whose volume is mostly the imperfect volume's voxels (R5.14,
# placed by iv_resolution, not grid), which IV_CONFIG's cases check
SMALL_CONFIG = {"technique": "lpv", "grid": [16, 16, 16], "iterations": 4, "rsm_size": 64, "normal_bins": False,
                "far_field": False}
