#!/usr/bin/env python3
"""make_scenes.py - writes the accuracy sweep's extra test scenes (docs/accuracy.md)
as glTF 2.0 binary files next to this script. Python standard library only.

  courtyard.glb  OPEN and LARGE: a 24 m plaza with buildings of several colours,
                 no roof, a directional sun (KHR_lights_punctual, lux).
  blinds.glb     THIN OCCLUDERS: a room divided by a 4 cm wall with a doorway,
                 a window with thin slats, lit by a spot light (candela) shining
                 through the slats; the front wall is left open for the camera.

Every object is an axis-aligned box (12 triangles); each material is one mesh.
lpvd divides the photometric light units by 683 lm/W (docs/units.md).

  python3 scenes/make_scenes.py            # rewrites scenes/*.glb
"""
import json
import math
import os
import struct
import sys


def box(lo, hi):
    """24 vertices (flat normals) and 36 indices of the box [lo, hi]."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    faces = [  # normal, 4 corners counter-clockwise seen from outside
        ((1, 0, 0), [(x1, y0, z1), (x1, y0, z0), (x1, y1, z0), (x1, y1, z1)]),
        ((-1, 0, 0), [(x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)]),
        ((0, 1, 0), [(x0, y1, z1), (x1, y1, z1), (x1, y1, z0), (x0, y1, z0)]),
        ((0, -1, 0), [(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)]),
        ((0, 0, 1), [(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]),
        ((0, 0, -1), [(x1, y0, z0), (x0, y0, z0), (x0, y1, z0), (x1, y1, z0)]),
    ]
    pos, nrm, idx = [], [], []
    for n, quad in faces:
        base = len(pos)
        pos.extend(quad)
        nrm.extend([n] * 4)
        idx.extend([base, base + 1, base + 2, base, base + 2, base + 3])
    return pos, nrm, idx


def normalize(v):
    length = math.sqrt(sum(c * c for c in v))
    return tuple(c / length for c in v)


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def look_rotation(forward, up=(0.0, 1.0, 0.0)):
    """Quaternion (x, y, z, w) turning the node's -Z into forward, +Y towards up."""
    f = normalize(forward)
    if abs(sum(a * b for a, b in zip(f, up))) > 0.999:
        up = (0.0, 0.0, -1.0)
    r = normalize(cross(f, up))
    u = cross(r, f)
    z = (-f[0], -f[1], -f[2])
    m = [[r[0], u[0], z[0]], [r[1], u[1], z[1]], [r[2], u[2], z[2]]]  # columns r, u, z
    tr = m[0][0] + m[1][1] + m[2][2]
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        return ((m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, 0.25 * s)
    if m[0][0] > m[1][1] and m[0][0] > m[2][2]:
        s = math.sqrt(1.0 + m[0][0] - m[1][1] - m[2][2]) * 2
        return (0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s, (m[2][1] - m[1][2]) / s)
    if m[1][1] > m[2][2]:
        s = math.sqrt(1.0 + m[1][1] - m[0][0] - m[2][2]) * 2
        return ((m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s, (m[0][2] - m[2][0]) / s)
    s = math.sqrt(1.0 + m[2][2] - m[0][0] - m[1][1]) * 2
    return ((m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s, (m[1][0] - m[0][1]) / s)


class Scene:
    def __init__(self):
        self.materials = []  # (name, rgb)
        self.boxes = {}      # material index -> list of (lo, hi)
        self.nodes = []
        self.lights = []
        self.cameras = []

    def material(self, name, rgb):
        self.materials.append((name, rgb))
        self.boxes[len(self.materials) - 1] = []
        return len(self.materials) - 1

    def add_box(self, mat, lo, hi):
        self.boxes[mat].append((lo, hi))

    def light(self, name, light, position, target):
        self.lights.append(dict(light, name=name))
        fwd = tuple(t - p for t, p in zip(target, position))
        self.nodes.append({"name": name, "translation": list(position),
                           "rotation": list(look_rotation(fwd)),
                           "extensions": {"KHR_lights_punctual": {"light": len(self.lights) - 1}}})

    def camera(self, name, eye, target, yfov_deg, aspect=1.0):
        self.cameras.append({"name": name, "type": "perspective",
                             "perspective": {"yfov": math.radians(yfov_deg), "aspectRatio": aspect,
                                             "znear": 0.05, "zfar": 200.0}})
        fwd = tuple(t - e for t, e in zip(target, eye))
        self.nodes.append({"name": name, "translation": list(eye), "rotation": list(look_rotation(fwd)),
                           "camera": len(self.cameras) - 1})

    def glb(self):
        blob = bytearray()
        views, accessors, meshes, mesh_nodes = [], [], [], []
        triangles = 0

        def add_view(data, target):
            while len(blob) % 4:
                blob.append(0)
            views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data), "target": target})
            blob.extend(data)
            return len(views) - 1

        for m, (name, _) in enumerate(self.materials):
            pos, nrm, idx = [], [], []
            for lo, hi in self.boxes[m]:
                p, n, i = box(lo, hi)
                idx.extend(len(pos) + k for k in i)
                pos.extend(p)
                nrm.extend(n)
            if not pos:
                continue
            triangles += len(idx) // 3
            pv = add_view(struct.pack("<%df" % (3 * len(pos)), *[c for v in pos for c in v]), 34962)
            nv = add_view(struct.pack("<%df" % (3 * len(nrm)), *[c for v in nrm for c in v]), 34962)
            iv = add_view(struct.pack("<%dH" % len(idx), *idx), 34963)
            lo = [min(v[k] for v in pos) for k in range(3)]
            hi = [max(v[k] for v in pos) for k in range(3)]
            accessors.append({"bufferView": pv, "componentType": 5126, "count": len(pos), "type": "VEC3",
                              "min": lo, "max": hi})
            accessors.append({"bufferView": nv, "componentType": 5126, "count": len(nrm), "type": "VEC3"})
            accessors.append({"bufferView": iv, "componentType": 5123, "count": len(idx), "type": "SCALAR"})
            a = len(accessors) - 3
            meshes.append({"name": name, "primitives": [{"attributes": {"POSITION": a, "NORMAL": a + 1},
                                                         "indices": a + 2, "material": m}]})
            mesh_nodes.append({"name": name, "mesh": len(meshes) - 1})
        while len(blob) % 4:
            blob.append(0)
        nodes = mesh_nodes + self.nodes
        doc = {
            "asset": {"version": "2.0", "generator": "lpvd scenes/make_scenes.py"},
            "extensionsUsed": ["KHR_lights_punctual"],
            "extensions": {"KHR_lights_punctual": {"lights": self.lights}},
            "scene": 0,
            "scenes": [{"nodes": list(range(len(nodes)))}],
            "nodes": nodes,
            "meshes": meshes,
            "materials": [{"name": n, "pbrMetallicRoughness": {"baseColorFactor": list(c) + [1.0],
                                                               "metallicFactor": 0.0, "roughnessFactor": 1.0}}
                          for n, c in self.materials],
            "cameras": self.cameras,
            "buffers": [{"byteLength": len(blob)}],
            "bufferViews": views,
            "accessors": accessors,
        }
        js = json.dumps(doc, separators=(",", ":")).encode()
        js += b" " * (-len(js) % 4)
        out = struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(js) + 8 + len(blob))
        out += struct.pack("<II", len(js), 0x4E4F534A) + js
        out += struct.pack("<II", len(blob), 0x004E4942) + bytes(blob)
        return out, triangles


def courtyard():
    s = Scene()
    ground = s.material("paving", (0.55, 0.52, 0.48))
    grass = s.material("grass", (0.12, 0.35, 0.08))
    red = s.material("red_brick", (0.60, 0.18, 0.12))
    yellow = s.material("yellow_render", (0.80, 0.65, 0.25))
    white = s.material("white_render", (0.80, 0.80, 0.78))
    blue = s.material("blue_glass_block", (0.15, 0.25, 0.55))
    s.add_box(ground, (-12, -0.2, -12), (12, 0.0, 12))
    s.add_box(grass, (-3, 0.0, -3), (3, 0.05, 3))
    s.add_box(red, (-11, 0, -11), (-4, 9, -5))         # tall building, back left
    s.add_box(yellow, (3, 0, -11), (11, 6, -6))        # back right
    s.add_box(white, (-11, 0, 3), (-6, 4, 11))         # front left, low
    s.add_box(blue, (6, 0, 2), (10, 12, 6))            # tower, right
    s.add_box(white, (-1.5, 0, -8), (1.5, 3, -6.5))    # kiosk between the back buildings
    s.add_box(red, (-0.4, 0, -0.4), (0.4, 2.5, 0.4))   # a column in the middle of the lawn
    s.light("sun", {"type": "directional", "color": [1.0, 0.95, 0.85], "intensity": 4000.0},
            (0, 30, 0), (0.45, 30 - 0.8, 0.4))
    s.camera("Camera", (-2, 14, 22), (0, 1, -1), 50.0)
    return s


def blinds():
    s = Scene()
    wall = s.material("walls", (0.75, 0.75, 0.72))
    floor = s.material("floor_wood", (0.55, 0.35, 0.18))
    divider = s.material("divider_green", (0.20, 0.55, 0.25))
    slat = s.material("slats", (0.85, 0.85, 0.85))
    sofa = s.material("sofa_red", (0.70, 0.12, 0.10))
    t = 0.1  # outer wall thickness
    s.add_box(floor, (-3 - t, -t, -2 - t), (3 + t, 0, 2))             # floor
    s.add_box(wall, (-3 - t, 3, -2 - t), (3 + t, 3 + t, 2))             # ceiling
    s.add_box(wall, (-3 - t, 0, -2 - t), (3 + t, 3, -2))                # back wall
    s.add_box(wall, (-3 - t, 0, -2), (-3, 3, 2))                        # left wall
    # right wall (x = 3) with a window z in [-1, 1], y in [0.9, 2.3]
    s.add_box(wall, (3, 0, -2), (3 + t, 0.9, 2))
    s.add_box(wall, (3, 2.3, -2), (3 + t, 3, 2))
    s.add_box(wall, (3, 0.9, -2), (3 + t, 2.3, -1))
    s.add_box(wall, (3, 0.9, 1), (3 + t, 2.3, 2))
    # the thin divider at x = 0 (4 cm) with a doorway z in [-0.6, 0.4], y < 2.1
    d = 0.02
    s.add_box(divider, (-d, 0, -2), (d, 3, -0.6))
    s.add_box(divider, (-d, 0, 0.4), (d, 3, 2))
    s.add_box(divider, (-d, 2.1, -0.6), (d, 3, 0.4))
    # slats (blinds) just inside the window: 2 cm thick boards every 14 cm
    y = 0.95
    while y < 2.3:
        s.add_box(slat, (2.85, y, -1.0), (2.95, y + 0.02, 1.0))
        y += 0.14
    s.add_box(sofa, (1.0, 0, -1.9), (2.4, 0.45, -1.1))                  # in the lit half
    s.add_box(sofa, (-2.5, 0, -1.9), (-1.2, 0.8, -1.4))                 # in the dark half
    s.light("spot", {"type": "spot", "color": [1.0, 0.9, 0.75], "intensity": 80000.0,
                     "spot": {"innerConeAngle": 0.25, "outerConeAngle": 0.45}},
            (5.5, 3.6, 0.0), (1.2, 0.0, -0.2))
    s.camera("Camera", (-2.2, 2.0, 6.5), (0.4, 1.1, 0.0), 50.0)
    return s


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    for name, build in (("courtyard", courtyard), ("blinds", blinds)):
        data, tris = build().glb()
        if tris >= 2000:
            sys.exit("%s: %d triangles, over the 2000 budget" % (name, tris))
        with open(os.path.join(here, name + ".glb"), "wb") as f:
            f.write(data)
        print("%s.glb: %d triangles, %d bytes" % (name, tris, len(data)))


if __name__ == "__main__":
    main()
