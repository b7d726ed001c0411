#!/usr/bin/env python3
"""make_scenes.py - writes the accuracy sweep's extra test scenes (docs/accuracy.md)
as glTF 2.0 binary files next to this script. Python standard library only.

  courtyard.glb  OPEN and LARGE: a 24 m plaza with buildings of several colours,
                 no roof, a directional sun (KHR_lights_punctual, lux).
  blinds.glb     THIN OCCLUDERS: a room divided by a 4 cm wall with a doorway,
                 a window with thin slats, lit by a spot light (candela) shining
                 through the slats; the front wall is left open for the camera.
  glossy.glb     GLOSSY: a closed 4 m room of matte walls, one red wall, a floor of
                 roughness 0.1 (every other material roughness 1), a point light
                 and a camera looking at the floor and the red wall.
  fog.glb        MEDIA: the room filled with homogeneous fog (scene extras
                 "lpvd_medium", sigma_s 0.08, sigma_a 0.02 1/m) and a spot light
                 whose beam crosses the view.
  smoke.glb      MEDIA: the room with a boxed 8x8x8 density texture of a soft
                 blob of smoke (sigma_s 0.5 1/m) lit by a spot light.
  emissive-room.glb  EMISSIVE ONLY (issue 10, docs/area-lights.md): the room lit
                 by two emissive surfaces and nothing else: a ceiling panel
                 (one quad facing down) and a wall strip (one quad facing into
                 the room); a table and a block cast their shadows.
  lamp-box.glb   ENCLOSED LIGHT (issue 30): the room with a closed 0.6 m box
                 (2 cm walls) on a plinth, a point light inside it and
                 nothing else: every surface in view must stay black.
  lamp-box-panel.glb  the same box holding an emissive panel (facing up,
                 under the box's lid) instead of the point light.
  lamp-open.glb  the same room, plinth and lamp with the box's lid and walls
                 left out: the light the enclosed lamp would give if it leaked
                 (the 1 % target of issue 30 is measured against it).
  two-rooms.glb  ENCLOSED ROOM: two rooms sharing a closed 10 cm wall, a point
                 light in the left one, the camera in the right one (dark).
  two-rooms-lit.glb  the same with the lamp in the camera's room (the 1 %
                 target of issue 30 is measured against it).
  panel-room.glb DOUBLE-SIDED EMITTER (issue 30): a closed 5 x 2.8 x 4 m dining
                 room lit only by a lamp panel hanging 0.5 m under the ceiling
                 over the table, its front facing the ceiling, glTF doubleSided
                 true: it lights the ceiling with its front and the table and
                 floor with its back, as glTF viewers light it.
  lamp-fixture.glb  ENCLOSED LIGHT IN A LARGE SCENE (issue 30, docs/shadows.md
                 "Near planes"): a 400 m ground with a point light in a closed
                 0.2 m box and an emissive panel in a closed 0.3 m box, and
                 the same two lamps without their boxes for comparison: only
                 the open lamps may light the ground.
  tunnel.glb     LONG (issue 30, docs/scenes.md "Defaults"): a closed tunnel
                 240 m long, 3 m wide and 2.6 m high (walls, floor, roof and
                 end caps 20 cm thick), lit from inside by six point lights
                 (candela) 40 m apart under the roof; NO camera, so the
                 default camera's rule for long scenes places the view.
  tunnel-terrain.glb  the tunnel under a 240 m x 240 m, 10 m thick block of
                 ground (issue 30): wide bounds, narrow air; a camera inside,
                 2 m from a lamp, looking along it (docs/cascades.md, "Long scenes").
  tunnel-hill.glb  the tunnel without its roof, the hill's underside its
                 ceiling: each lamp 0.2 m under a solid 10 m thick, in reach
                 voxels of 0.78 m (docs/propagation.md, "Enclosed lights").
  curved.glb     CURVED (issue 30): the room with a smooth-shaded white sphere
                 and a smooth-shaded grey cylinder on its floor, lit by a spot
                 light from above the red wall; the camera sees both where they
                 turn away from the light (their indirect light should vary
                 smoothly across voxels).
  box-walls.glb  THICK WALLS (issue 30, docs/imperfect-volumes.md "Limits"): the
                 closed room of 10 cm box walls (each wall's two faces share a
                 voxel of the imperfect volume), empty, lit by glossy.glb's
                 point light; thin-walls.glb is the same room of single quads
                 facing in. The pair isolates what thick walls cost a
                 technique (the imperfect volume's first bounce: -0.105
                 against -0.017).

  glass.glb      TRANSLUCENT (issue 32, docs/scenes.md "Alpha"): the room lit by a
                 spot light shining down through a blue-green pane of alpha 0.4
                 (alphaMode BLEND, double-sided) hanging 1.4 m over the floor,
                 and a red pane of alpha 0.7 standing before the back wall:
                 the floor under the first gets 60 % of the spot's light.

Every object is an axis-aligned box (12 triangles), a quad (2 triangles, its
front the side its corners run counter-clockwise around), or a UV sphere or
upright cylinder with smooth vertex normals; each material is one mesh.
Emission is glTF's emissiveFactor x KHR_materials_emissive_strength (nits);
materials are single-sided (glTF's default) unless made with double_sided=True.
lpvd divides the photometric light units by 683 lm/W (docs/units.md); the
medium format is in docs/scenes.md.

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


def sphere(centre, radius, rings=16, segments=24):
    """A UV sphere with smooth (radial) normals: vertices and indices."""
    pos, nrm, idx = [], [], []
    for i in range(rings + 1):
        th = math.pi * i / rings
        for j in range(segments + 1):
            ph = 2.0 * math.pi * j / segments
            n = (math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph))
            nrm.append(n)
            pos.append(tuple(c + radius * k for c, k in zip(centre, n)))
    for i in range(rings):
        for j in range(segments):
            a, b = i * (segments + 1) + j, (i + 1) * (segments + 1) + j
            idx.extend([a, a + 1, b, a + 1, b + 1, b])  # counter-clockwise seen from outside
    return pos, nrm, idx


def cylinder(base, radius, height, segments=32):
    """An upright open cylinder (side only) with smooth (horizontal) normals."""
    pos, nrm, idx = [], [], []
    for j in range(segments + 1):
        ph = 2.0 * math.pi * j / segments
        n = (math.cos(ph), 0.0, math.sin(ph))
        for h in (0.0, height):
            nrm.append(n)
            pos.append((base[0] + radius * n[0], base[1] + h, base[2] + radius * n[2]))
    for j in range(segments):
        a = 2 * j
        idx.extend([a, a + 1, a + 2, a + 1, a + 3, a + 2])  # counter-clockwise seen from outside
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
        self.materials = []  # (name, rgb, roughness, emission, double_sided): emission None or
                             # (rgb factor, strength in nits)
        self.boxes = {}      # material index -> list of (lo, hi)
        self.quads = {}      # material index -> list of 4 corners (counter-clockwise seen from the front)
        self.meshes = {}     # material index -> list of (positions, normals, indices): spheres, cylinders
        self.nodes = []
        self.lights = []
        self.cameras = []
        self.medium = None   # lpvd_medium object for the scene's extras, or None
        self.alphas = {}     # material index -> None (opaque) or a BLEND alpha

    def material(self, name, rgb, roughness=1.0, emission=None, double_sided=False, alpha=None):
        """alpha: None for an opaque material, else alphaMode BLEND with this alpha (coverage)."""
        self.materials.append((name, rgb, roughness, emission, double_sided))
        self.alphas[len(self.materials) - 1] = alpha
        self.boxes[len(self.materials) - 1] = []
        self.quads[len(self.materials) - 1] = []
        self.meshes[len(self.materials) - 1] = []
        return len(self.materials) - 1

    def add_box(self, mat, lo, hi):
        self.boxes[mat].append((lo, hi))

    def add_quad(self, mat, corners):
        self.quads[mat].append(corners)

    def add_mesh(self, mat, mesh):
        self.meshes[mat].append(mesh)

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

        for m, (name, _, _, _, _) in enumerate(self.materials):
            pos, nrm, idx = [], [], []
            for lo, hi in self.boxes[m]:
                p, n, i = box(lo, hi)
                idx.extend(len(pos) + k for k in i)
                pos.extend(p)
                nrm.extend(n)
            for q in self.quads[m]:
                e1 = tuple(b - a for a, b in zip(q[0], q[1]))
                e2 = tuple(b - a for a, b in zip(q[0], q[2]))
                n = normalize(cross(e1, e2))
                base = len(pos)
                pos.extend(q)
                nrm.extend([n] * 4)
                idx.extend([base, base + 1, base + 2, base, base + 2, base + 3])
            for p, n, i in self.meshes[m]:
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
        scene = {"nodes": list(range(len(nodes)))}
        if self.medium is not None:
            scene["extras"] = {"lpvd_medium": self.medium}
        materials = []
        for k, (n, c, r, e, two) in enumerate(self.materials):
            alpha = self.alphas[k]
            mat = {"name": n, "pbrMetallicRoughness": {"baseColorFactor": list(c) + [1.0 if alpha is None else alpha],
                                                       "metallicFactor": 0.0, "roughnessFactor": r}}
            if alpha is not None:
                mat["alphaMode"] = "BLEND"
            if two:
                mat["doubleSided"] = True
            if e is not None:
                mat["emissiveFactor"] = list(e[0])
                mat["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": e[1]}}
            materials.append(mat)
        used = ["KHR_lights_punctual"] if self.lights else []
        if any(e is not None for _, _, _, e, _ in self.materials):
            used.append("KHR_materials_emissive_strength")
        doc = {"asset": {"version": "2.0", "generator": "lpvd scenes/make_scenes.py"}, "extensionsUsed": used}
        if self.lights:
            doc["extensions"] = {"KHR_lights_punctual": {"lights": self.lights}}
        doc.update({
            "scene": 0,
            "scenes": [scene],
            "nodes": nodes,
            "meshes": meshes,
            "materials": materials,
            "cameras": self.cameras,
            "buffers": [{"byteLength": len(blob)}],
            "bufferViews": views,
            "accessors": accessors,
        })
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


def room(s, floor_roughness=1.0):
    """A closed room x, z in [-2, 2], y in [0, 3] (walls 10 cm thick), matte
    except the floor; the left wall (x = -2) is red. Returns the floor material."""
    wall = s.material("walls", (0.75, 0.75, 0.72))
    red = s.material("red_wall", (0.70, 0.12, 0.10))
    floor = s.material("floor", (0.45, 0.45, 0.45), floor_roughness)
    t = 0.1
    s.add_box(floor, (-2 - t, -t, -2 - t), (2 + t, 0, 2 + t))   # floor
    s.add_box(wall, (-2 - t, 3, -2 - t), (2 + t, 3 + t, 2 + t))   # ceiling
    s.add_box(wall, (-2, 0, -2 - t), (2, 3, -2))                  # back wall
    s.add_box(wall, (-2, 0, 2), (2, 3, 2 + t))                    # front wall (behind the camera)
    s.add_box(red, (-2 - t, 0, -2 - t), (-2, 3, 2 + t))           # left wall, coloured
    s.add_box(wall, (2, 0, -2 - t), (2 + t, 3, 2 + t))            # right wall
    return floor


def glossy():
    s = Scene()
    room(s, floor_roughness=0.1)
    block = s.material("block_white", (0.80, 0.80, 0.80))
    s.add_box(block, (0.4, 0, -1.2), (1.2, 0.8, -0.4))
    # 4600 cd = 6.7 W/sr: about 1 W/m^2 on the floor 2.6 m below
    s.light("point", {"type": "point", "color": [1.0, 0.95, 0.9], "intensity": 4600.0}, (0.3, 2.6, 0.2),
            (0.3, 0.0, 0.2))
    s.camera("Camera", (1.2, 1.6, 1.8), (-1.4, 0.4, -0.8), 60.0)
    return s


def fog():
    s = Scene()
    room(s)
    s.medium = {"sigma_s": 0.08, "sigma_a": 0.02}
    # a spot from the upper right-back corner down towards the left front floor
    s.light("spot", {"type": "spot", "color": [1.0, 0.92, 0.8], "intensity": 30000.0,
                     "spot": {"innerConeAngle": 0.12, "outerConeAngle": 0.22}},
            (1.8, 2.9, -1.8), (-1.0, 0.0, 0.6))
    s.camera("Camera", (1.0, 1.5, 1.9), (-0.6, 1.0, -1.0), 60.0)
    return s


def smoke_blob(n=8):
    """n^3 densities (x fastest) of a soft Gaussian blob, rounded to keep the file small."""
    values = []
    for k in range(n):
        for j in range(n):
            for i in range(n):
                x, y, z = ((c + 0.5) / n * 2.0 - 1.0 for c in (i, j, k))
                values.append(round(math.exp(-2.5 * (x * x + 1.5 * y * y + z * z)), 3))
    return values


def smoke():
    s = Scene()
    room(s)
    s.medium = {"sigma_s": 0.5, "sigma_a": 0.05,
                "box": {"min": [-1.0, 0.2, -1.2], "max": [1.0, 2.2, 0.8]},
                "density": {"dims": [8, 8, 8], "values": smoke_blob(8)}}
    s.light("spot", {"type": "spot", "color": [1.0, 0.92, 0.8], "intensity": 30000.0,
                     "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.35}},
            (1.8, 2.9, -1.8), (0.0, 1.2, -0.2))
    s.camera("Camera", (1.0, 1.5, 1.9), (-0.2, 1.1, -0.4), 60.0)
    return s


def emissive_room():
    s = Scene()
    room(s)
    wood = s.material("table_wood", (0.55, 0.35, 0.18))
    block = s.material("block_white", (0.80, 0.80, 0.80))
    # 2 W/(m^2 sr) (1366 nits / 683 lm/W): a 1.2 x 0.6 m panel 5 cm under the ceiling, facing down
    panel = s.material("ceiling_panel", (0.9, 0.9, 0.9), emission=((1.0, 0.95, 0.85), 1366.0))
    s.add_quad(panel, [(-0.6, 2.95, -0.3), (0.6, 2.95, -0.3), (0.6, 2.95, 0.3), (-0.6, 2.95, 0.3)])
    # a warm strip on the back wall, 1.6 x 0.15 m at 1.8 m, facing into the room (+z)
    strip = s.material("wall_strip", (0.9, 0.9, 0.9), emission=((1.0, 0.6, 0.3), 2049.0))
    s.add_quad(strip, [(-0.8, 1.75, -1.99), (0.8, 1.75, -1.99), (0.8, 1.9, -1.99), (-0.8, 1.9, -1.99)])
    s.add_box(wood, (-0.7, 0.72, -0.5), (0.5, 0.77, 0.3))     # table top under the panel
    for x, z in ((-0.65, -0.45), (0.45, -0.45), (-0.65, 0.25), (0.45, 0.25)):
        s.add_box(wood, (x, 0.0, z), (x + 0.05, 0.72, z + 0.05))  # its legs
    s.add_box(block, (0.9, 0.0, -1.5), (1.5, 1.1, -0.9))      # a block near the back wall
    s.camera("Camera", (1.4, 1.7, 1.9), (-0.5, 0.7, -0.8), 65.0)
    return s


def lamp_box(light="point", enclosed=True):
    """The room with a 0.6 m box of 2 cm walls on a 0.5 m plinth; inside it a
    point light (light="point") or an emissive panel facing up (light="panel").
    enclosed=False leaves out the box's lid and four walls (the lamp and the
    box's floor stay), so the lamp lights the room."""
    s = Scene()
    room(s)
    grey = s.material("box_grey", (0.60, 0.60, 0.60))
    plinth = s.material("plinth", (0.50, 0.45, 0.40))
    s.add_box(plinth, (-0.4, 0.0, -0.9), (0.4, 0.5, -0.1))
    lo, hi, t = (-0.3, 0.5, -0.8), (0.3, 1.1, -0.2), 0.02
    s.add_box(grey, (lo[0], lo[1], lo[2]), (hi[0], lo[1] + t, hi[2]))              # box floor
    if enclosed:
        s.add_box(grey, (lo[0], hi[1] - t, lo[2]), (hi[0], hi[1], hi[2]))          # lid
        s.add_box(grey, (lo[0], lo[1], lo[2]), (lo[0] + t, hi[1], hi[2]))          # walls
        s.add_box(grey, (hi[0] - t, lo[1], lo[2]), (hi[0], hi[1], hi[2]))
        s.add_box(grey, (lo[0], lo[1], lo[2]), (hi[0], hi[1], lo[2] + t))
        s.add_box(grey, (lo[0], lo[1], hi[2] - t), (hi[0], hi[1], hi[2]))
    if light == "point":
        # 4600 cd = 6.7 W/sr
        s.light("lamp", {"type": "point", "color": [1.0, 0.95, 0.9], "intensity": 4600.0}, (0.0, 0.8, -0.5),
                (0.0, 0.0, -0.5))
    else:
        # 20 W/(m^2 sr) (13660 nits): a 0.3 x 0.3 m panel 5 cm under the lid, facing up
        panel = s.material("lamp_panel", (0.9, 0.9, 0.9), emission=((1.0, 0.95, 0.85), 13660.0))
        y = hi[1] - t - 0.05
        s.add_quad(panel, [(-0.15, y, -0.35), (-0.15, y, -0.65), (0.15, y, -0.65), (0.15, y, -0.35)])
    s.camera("Camera", (1.4, 1.7, 1.9), (-0.3, 0.8, -0.8), 65.0)
    return s


def two_rooms(lit_side=-1):
    """Two 4 x 3 x 4 m rooms side by side (x in [-4, 0] and [0, 4]) sharing a
    closed 10 cm wall at x = 0; a point light in the left room (lit_side -1)
    or in the right one (+1), the camera in the right one looking at the
    shared wall."""
    s = Scene()
    wall = s.material("walls", (0.75, 0.75, 0.72))
    floor = s.material("floor", (0.45, 0.45, 0.45))
    t = 0.1
    s.add_box(floor, (-4 - t, -t, -2 - t), (4 + t, 0, 2 + t))
    s.add_box(wall, (-4 - t, 3, -2 - t), (4 + t, 3 + t, 2 + t))
    s.add_box(wall, (-4 - t, 0, -2 - t), (4 + t, 3, -2))             # back
    s.add_box(wall, (-4 - t, 0, 2), (4 + t, 3, 2 + t))               # front
    s.add_box(wall, (-4 - t, 0, -2), (-4, 3, 2))                     # left end
    s.add_box(wall, (4, 0, -2), (4 + t, 3, 2))                       # right end
    s.add_box(wall, (-t / 2, 0, -2), (t / 2, 3, 2))                  # the shared wall
    s.light("lamp", {"type": "point", "color": [1.0, 0.95, 0.9], "intensity": 4600.0}, (2.0 * lit_side, 2.2, 0.0),
            (2.0 * lit_side, 0.0, 0.0))
    s.camera("Camera", (3.6, 1.6, 1.6), (0.0, 1.2, -0.6), 70.0)
    return s


def panel_room():
    s = Scene()
    # a closed room x in [-2.5, 2.5], z in [-2, 2], y in [0, 2.8] (walls 10 cm thick)
    wall = s.material("walls", (0.78, 0.76, 0.72))
    floor = s.material("floor", (0.42, 0.36, 0.30))
    green = s.material("green_wall", (0.25, 0.45, 0.30))
    wood = s.material("table_wood", (0.55, 0.35, 0.18))
    t = 0.1
    s.add_box(floor, (-2.5 - t, -t, -2 - t), (2.5 + t, 0, 2 + t))      # floor
    s.add_box(wall, (-2.5 - t, 2.8, -2 - t), (2.5 + t, 2.8 + t, 2 + t))  # ceiling
    s.add_box(wall, (-2.5, 0, -2 - t), (2.5, 2.8, -2))                  # back wall
    s.add_box(wall, (-2.5, 0, 2), (2.5, 2.8, 2 + t))                    # front wall (behind the camera)
    s.add_box(green, (-2.5 - t, 0, -2 - t), (-2.5, 2.8, 2 + t))         # left wall, coloured
    s.add_box(wall, (2.5, 0, -2 - t), (2.5 + t, 2.8, 2 + t))            # right wall
    s.add_box(wood, (-0.9, 0.72, -0.45), (0.9, 0.77, 0.45))             # the dining table
    for x, z in ((-0.85, -0.4), (0.8, -0.4), (-0.85, 0.35), (0.8, 0.35)):
        s.add_box(wood, (x, 0.0, z), (x + 0.05, 0.72, z + 0.05))        # its legs
    # the lamp: 2 W/(m^2 sr) (1366 nits / 683 lm/W) from each side, a 1.2 x 0.4 m
    # panel 0.5 m under the ceiling, its front (counter-clockwise seen from
    # above) facing the ceiling; doubleSided, so its back lights the table
    panel = s.material("lamp_panel", (0.9, 0.9, 0.9), emission=((1.0, 0.95, 0.85), 1366.0), double_sided=True)
    s.add_quad(panel, [(-0.6, 2.3, 0.2), (0.6, 2.3, 0.2), (0.6, 2.3, -0.2), (-0.6, 2.3, -0.2)])
    s.camera("Camera", (2.1, 1.6, 1.7), (-0.6, 1.2, -0.9), 70.0)
    return s


def tunnel():
    s = Scene()
    wall = s.material("tunnel_walls", (0.60, 0.58, 0.55))
    floor = s.material("tunnel_floor", (0.35, 0.35, 0.36))
    red = s.material("end_cap_red", (0.65, 0.15, 0.10))
    L, W, H, t = 120.0, 1.5, 2.6, 0.2  # half length and half width, height, wall thickness
    s.add_box(floor, (-W - t, -t, -L - t), (W + t, 0, L + t))          # floor
    s.add_box(wall, (-W - t, H, -L - t), (W + t, H + t, L + t))         # roof
    s.add_box(wall, (-W - t, 0, -L - t), (-W, H, L + t))                # left wall
    s.add_box(wall, (W, 0, -L - t), (W + t, H, L + t))                  # right wall
    s.add_box(red, (-W, 0, -L - t), (W, H, -L))                         # end cap, far (-z)
    s.add_box(wall, (-W, 0, L), (W, H, L + t))                          # end cap, near (+z)
    # 1500 cd = 2.2 W/sr: about 0.4 W/m^2 on the floor 2.4 m below each light
    for z in (-100.0, -60.0, -20.0, 20.0, 60.0, 100.0):
        s.light("lamp_%+d" % int(z), {"type": "point", "color": [1.0, 0.9, 0.75], "intensity": 1500.0},
                (0.0, H - 0.2, z), (0.0, 0.0, z))
    return s


def tunnel_terrain():
    """The tunnel under a hill: the same tunnel with a 10 m thick block of
    ground over it, 240 m x 240 m, so its bounds are wide, not long, and only
    the space around the camera says how narrow its air is; the camera stands
    inside, 2 m from a lamp, looking along it."""
    s = tunnel()
    ground = s.material("hill_ground", (0.40, 0.38, 0.30))
    s.add_box(ground, (-120.0, 2.8, -120.2), (120.0, 12.8, 120.2))
    s.camera("Camera", (0.0, 1.6, -58.0), (0.0, 1.3, -100.0), 70.0)
    return s


def tunnel_hill():
    """The tunnel whose ceiling is the hill's own underside: no roof of its
    own, the 240 m x 240 m block of ground 10 m thick resting on its walls,
    so each lamp hangs 0.2 m under a solid 10 m thick. In a 240 m scene the
    reach voxels are 0.78 m, every lamp's voxel is solid, and the voxels
    alone cannot tell the tunnel's air from the hill's hollow inside
    (docs/propagation.md, "Enclosed lights"). The camera as in
    tunnel-terrain."""
    s = tunnel()
    s.boxes = {m: [b for b in boxes if b[0][1] != 2.6] for m, boxes in s.boxes.items()}  # no roof
    ground = s.material("hill_ground", (0.40, 0.38, 0.30))
    s.add_box(ground, (-120.0, 2.6, -120.2), (120.0, 12.6, 120.2))
    s.camera("Camera", (0.0, 1.6, -58.0), (0.0, 1.3, -100.0), 70.0)
    return s


def curved():
    s = Scene()
    room(s)
    white = s.material("sphere_white", (0.80, 0.80, 0.80))
    grey = s.material("cylinder_grey", (0.55, 0.55, 0.55))
    s.add_mesh(white, sphere((0.3, 0.8, -0.5), 0.8))
    s.add_mesh(grey, cylinder((-1.1, 0.0, 0.5), 0.45, 1.8))
    # from high above the red wall down onto the floor in front of the sphere
    s.light("spot", {"type": "spot", "color": [1.0, 0.95, 0.9], "intensity": 20000.0,
                     "spot": {"innerConeAngle": 0.5, "outerConeAngle": 0.7}},
            (-1.7, 2.9, -1.5), (0.8, 0.0, 0.6))
    s.camera("Camera", (1.6, 1.6, 1.9), (-0.2, 0.7, -0.3), 60.0)
    return s


def lamp_fixture():
    """A 400 m ground (so the scene's bounding radius is about 283 m) with,
    3 m apart: at the back, a point light 10 cm over the ground in a closed
    0.2 m box (left) and an emissive 10 cm panel facing down 5 cm under the
    lid of a closed 0.3 m box (right); at the front, the same two lamps
    without their boxes. The camera looks down at all four. The boxes' walls are nearer their lamps than the lights'
    old near planes (1e-3 x the radius, 0.28 m), which let the boxed lamps
    light the ground as the open ones do."""
    s = Scene()
    ground = s.material("ground", (0.50, 0.50, 0.50))
    grey = s.material("fixture_grey", (0.60, 0.60, 0.60))
    # 136600 nits = 200 W/(m^2 sr): 2 W/sr along the normal from 0.01 m^2
    panel = s.material("lamp_panel", (0.9, 0.9, 0.9), emission=((1.0, 0.95, 0.85), 136600.0))
    s.add_box(ground, (-200.0, -0.2, -200.0), (200.0, 0.0, 200.0))
    for z, enclosed in ((-1.5, True), (1.5, False)):
        x = -1.5
        if enclosed:
            s.add_box(grey, (x - 0.1, 0.0, z - 0.1), (x + 0.1, 0.2, z + 0.1))
        # 4600 cd = 6.7 W/sr
        s.light("lamp_%s" % ("boxed" if enclosed else "open"),
                {"type": "point", "color": [1.0, 0.95, 0.9], "intensity": 4600.0}, (x, 0.1, z), (x, 0.0, z))
    for z, enclosed in ((-1.5, True), (1.5, False)):
        x = 1.5
        if enclosed:
            s.add_box(grey, (x - 0.15, 0.0, z - 0.15), (x + 0.15, 0.3, z + 0.15))
        a, y = 0.05, 0.25  # counter-clockwise seen from below: facing down
        s.add_quad(panel, [(x - a, y, z - a), (x + a, y, z - a), (x + a, y, z + a), (x - a, y, z + a)])
    s.camera("Camera", (0.0, 6.0, 5.0), (0.0, 0.0, 0.0), 65.0)
    return s


def walls_room(thin):
    """glossy.glb's room and point light, empty: with its 10 cm box walls
    (thin=False, room()) or with six single quads facing in at the walls'
    inner faces (thin=True), same materials."""
    s = Scene()
    if thin:
        wall = s.material("walls", (0.75, 0.75, 0.72))
        red = s.material("red_wall", (0.70, 0.12, 0.10))
        floor = s.material("floor", (0.45, 0.45, 0.45))
        pos, _, idx = box((-2, 0, -2), (2, 3, 2))
        # box()'s faces face out, in the order +x, -x, +y, -y, +z, -z: each quad reversed faces in
        for k, mat in enumerate((wall, red, wall, floor, wall, wall)):
            s.add_quad(mat, list(reversed(pos[4 * k:4 * k + 4])))
    else:
        room(s)
    s.light("point", {"type": "point", "color": [1.0, 0.95, 0.9], "intensity": 4600.0}, (0.3, 2.6, 0.2),
            (0.3, 0.0, 0.2))
    s.camera("Camera", (1.2, 1.6, 1.8), (-1.4, 0.4, -0.8), 60.0)
    return s


def glass():
    s = Scene()
    room(s)
    # a spot from the ceiling straight down through a tinted pane (alpha 0.4:
    # 60 % of the light passes) hanging 1.4 m over the floor; an upright red
    # pane (alpha 0.7) stands in front of the back wall, both in view
    tinted = s.material("tinted_glass", (0.20, 0.55, 0.80), double_sided=True, alpha=0.4)
    red = s.material("red_glass", (0.85, 0.15, 0.10), double_sided=True, alpha=0.7)
    s.add_quad(tinted, [(-0.2, 1.4, 0.8), (1.4, 1.4, 0.8), (1.4, 1.4, -0.8), (-0.2, 1.4, -0.8)])
    s.add_quad(red, [(-1.4, 0.0, -1.0), (0.0, 0.0, -1.0), (0.0, 1.6, -1.0), (-1.4, 1.6, -1.0)])
    s.light("spot", {"type": "spot", "color": [1.0, 0.95, 0.9], "intensity": 12000.0,
                     "spot": {"innerConeAngle": 0.35, "outerConeAngle": 0.55}},
            (0.6, 2.9, 0.0), (0.6, 0.0, 0.0))
    s.camera("Camera", (1.6, 1.7, 1.9), (-0.4, 0.5, -1.0), 65.0)
    return s


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    for name, build in (("courtyard", courtyard), ("blinds", blinds), ("glossy", glossy), ("fog", fog),
                        ("smoke", smoke), ("emissive-room", emissive_room), ("lamp-box", lamp_box),
                        ("lamp-box-panel", lambda: lamp_box("panel")),
                        ("lamp-open", lambda: lamp_box(enclosed=False)),
                        ("lamp-open-panel", lambda: lamp_box("panel", enclosed=False)), ("two-rooms", two_rooms),
                        ("two-rooms-lit", lambda: two_rooms(+1)), ("panel-room", panel_room), ("tunnel", tunnel),
                        ("tunnel-terrain", tunnel_terrain), ("tunnel-hill", tunnel_hill),
                        ("curved", curved), ("lamp-fixture", lamp_fixture),
                        ("box-walls", lambda: walls_room(False)), ("thin-walls", lambda: walls_room(True)),
                        ("glass", glass)):
        data, tris = build().glb()
        if tris >= 2000:
            sys.exit("%s: %d triangles, over the 2000 budget" % (name, tris))
        with open(os.path.join(here, name + ".glb"), "wb") as f:
            f.write(data)
        print("%s.glb: %d triangles, %d bytes" % (name, tris, len(data)))


if __name__ == "__main__":
    main()
