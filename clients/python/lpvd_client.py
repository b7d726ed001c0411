#!/usr/bin/env python3
"""lpvd_client.py - a Python client for the lpvd wire protocol, version 1.

Standard library only (socket, struct, json, array). numpy is used when it
is importable (volumes and query answers then come back as float32 arrays);
the ``zstandard`` module is used when importable, otherwise the client asks
the server for ``"compression": "none"`` (the standard library has no zstd).

    from lpvd_client import Client
    with Client("/tmp/lpvd.sock") as c:      # connects and sends HELLO
        c.tick()
        vol = c.get_volume()                 # Volume: cascades, 12 floats per cell
        print(c.query_irradiance([(0, 1, 0)], [(0, 1, 0)]))

The protocol is protocol/SPEC.md; section numbers below refer to it.

Run ``python3 lpvd_client.py --self-test ADDRESS`` for a short end-to-end
check against a running daemon (exit status 0 on success).
"""

import array
import json
import math
import os
import socket
import struct
import sys

try:  # optional
    import numpy as _np
except ImportError:  # pragma: no cover - depends on the machine
    _np = None

try:  # optional
    import zstandard as _zstd
except ImportError:  # pragma: no cover - depends on the machine
    _zstd = None

__all__ = [
    "Client", "LpvdError", "ProtocolError", "Volume", "Frame",
    "default_address", "MSG", "HAVE_NUMPY", "HAVE_ZSTD",
]

HAVE_NUMPY = _np is not None
HAVE_ZSTD = _zstd is not None

MAGIC = b"LPVD"
VERSION = 1
HEADER = struct.Struct("<4sHHIIII")  # magic, version, type, request_id, flags, json_len, att_len
assert HEADER.size == 24

# Message types (SPEC section 4).
MSG = {
    "HELLO": 0x0001,
    "SCENE_LOAD": 0x0002,
    "SCENE_UPDATE": 0x0003,
    "LIGHT_SET": 0x0004,
    "LIGHT_REMOVE": 0x0005,
    "CAMERA_SET": 0x0006,
    "CONFIG": 0x0007,
    "TICK": 0x0008,
    "SUBSCRIBE": 0x0009,
    "UNSUBSCRIBE": 0x000A,
    "GET_VOLUME": 0x000B,
    "GET_FRAME": 0x000C,
    "QUERY_IRRADIANCE": 0x000D,
    "STATS": 0x000E,
    "BYE": 0x000F,
    "ACK": 0x0010,
    "VOLUME": 0x0101,
    "FRAME": 0x0102,
    "ERROR": 0xFFFF,
}
REPLY_BIT = 0x8000
SERVER_BYE = MSG["BYE"] | REPLY_BIT

# ERROR codes (SPEC R3.4).
ERROR_NAMES = {
    1: "BAD_MAGIC", 2: "BAD_VERSION", 3: "BAD_FRAME", 4: "TOO_LARGE",
    5: "BAD_JSON", 6: "UNKNOWN_TYPE", 7: "BAD_FIELD", 8: "UNAUTHORIZED",
    9: "HELLO_REQUIRED", 10: "NOT_READY", 11: "SCENE_INVALID",
    12: "PATH_REFUSED", 13: "LIMIT", 14: "INTERNAL", 15: "SHUTTING_DOWN",
}

# Two-band SH constants of docs/propagation.md section 1.
SH_LOBE0 = 0.886226925452758    # sqrt(pi) / 2
SH_LOBE1 = 1.0233267079464885   # sqrt(pi / 3)

MAX_CASCADES = 4  # entries of a volume header's "cascades" (SPEC R5.6)
# The description's layout version this client reads (SPEC R5.9); what a
# volume carries is read from the description itself.
VOLUME_LAYOUT_VERSION = 1
OCTREE_LEVEL_ROLE = "octree_level"  # the role of an octree's levels (SPEC R5.13, GET_VOLUME content "levels")
IV_VOXELS_ROLE = "iv_voxels"  # the role of technique iv's one level of voxels (SPEC R5.14)
IV_UNITS = "W/(m^2 sr)"  # an iv volume's values: the radiance arriving at each voxel centre (SPEC R5.14)
LPV_UNITS = "W/sr"  # an LPV's values: radiant intensity per cell, what R5.7's lookup reads
# The values, in order, that this client's lookup (Cascade.irradiance: the
# cosine lobe on SH bands 0-1 per channel) reads; a volume whose description
# names other values is decoded but not looked up (SPEC R5.11).
LOOKUP_VALUES = tuple("%s.%s" % (ch, y) for ch in "rgb" for y in ("Y00", "Y1-1", "Y10", "Y11"))
# The passes of a plan (SPEC section 8, R8.1), in order.
PLAN_PASSES = ("rsm", "emissive", "inject", "gbuffer", "gv", "propagate", "bounce", "glossy", "media")


def plan_lines(plan):
    """A tick plan (SPEC section 8) as human-readable lines, e.g. for
    printing STATS["plan"]["plan"] or a volume's ``plan``."""
    if not plan:
        return ["plan: none"]
    out = ["cascades: %s (%s)" % (plan.get("cascades"), plan.get("cascades_reason", "")),
           "recompute: %s (%s)" % ("yes" if plan.get("recompute") else "no", plan.get("recompute_reason", ""))]
    if plan.get("iterations_reason"):
        out.insert(1, "iterations%s: %s" % (" WARNING" if plan.get("iterations_warning") else "",
                                            plan["iterations_reason"]))
    for p in plan.get("passes", []):
        out.append("  %-10s %-4s %s" % (p.get("name"), "run" if p.get("run") else "skip", p.get("reason", "")))
    return out


class LpvdError(Exception):
    """An ERROR reply (SPEC R3.4): ``code``, ``name``, ``message``."""

    def __init__(self, code, name, message, body=None):
        Exception.__init__(self, "%s (%d): %s" % (name, code, message))
        self.code = code
        self.name = name
        self.message = message
        self.body = body or {}


class ProtocolError(Exception):
    """The connection broke, or the server sent something the protocol forbids."""


class LayoutError(ValueError):
    """A lookup on a volume whose described layout (SPEC R5.11) it does not read;
    the message names the layout."""


def default_address():
    """The daemon's default socket (SPEC R1.1)."""
    run = os.environ.get("XDG_RUNTIME_DIR")
    if run and os.path.isabs(run) and os.path.isdir(run):  # the daemon's rule (protocol/proto_address.c)
        return os.path.join(run, "lpvd.sock")
    return "/tmp/lpvd-%d.sock" % os.getuid()


def _parse_address(address):
    """'unix:PATH', 'tcp:HOST:PORT', 'HOST:PORT' or a socket path."""
    if address.startswith("unix:"):
        return ("unix", address[5:])
    if address.startswith("tcp:"):
        address = address[4:]
    elif "/" in address or ":" not in address:
        return ("unix", address)
    host, _, port = address.rpartition(":")
    if host.startswith("[") and host.endswith("]"):
        host = host[1:-1]
    if not port.isdigit():
        raise ValueError("bad address %r: expected HOST:PORT or a socket path" % address)
    return ("tcp", (host or "127.0.0.1", int(port)))


def _decompress(data, compression, raw_length):
    if compression in (None, "none"):
        return bytes(data)
    if compression == "zstd":
        if _zstd is None:
            raise ProtocolError("zstd-compressed attachment but the 'zstandard' module is not installed")
        return _zstd.ZstdDecompressor().decompress(data, max_output_size=max(raw_length, 1))
    raise ProtocolError("unknown compression %r" % compression)


def _default_compression():
    return "zstd" if _zstd is not None else "none"


def _xor(a, b):
    """Byte-wise XOR of two equally long byte strings (SPEC R5.3)."""
    if len(a) != len(b):
        raise ProtocolError("XOR delta of %d bytes against a base of %d bytes" % (len(a), len(b)))
    n = len(a)
    return (int.from_bytes(a, "little") ^ int.from_bytes(b, "little")).to_bytes(n, "little")


def _floats(raw, fmt):
    """Raw little-endian fp16/fp32 bytes -> float32 numpy array or array('f')."""
    if fmt == "fp32":
        if len(raw) % 4:
            raise ProtocolError("fp32 volume of %d bytes" % len(raw))
        if _np is not None:
            return _np.frombuffer(raw, dtype="<f4").copy()
        out = array.array("f")
        out.frombytes(raw)
        if sys.byteorder != "little":
            out.byteswap()
        return out
    if fmt == "fp16":
        if len(raw) % 2:
            raise ProtocolError("fp16 volume of %d bytes" % len(raw))
        if _np is not None:
            return _np.frombuffer(raw, dtype="<f2").astype(_np.float32)
        return array.array("f", struct.unpack("<%de" % (len(raw) // 2), raw))
    raise ProtocolError("unknown volume format %r" % fmt)


_F32 = struct.Struct("<f")


def _f32(x):
    """x rounded to the nearest binary32 (each step of SPEC R5.14's lookup is
    a binary32 operation; rounding the double result of one +, -, *, / or
    sqrt gives the binary32 result exactly)."""
    try:
        return _F32.unpack(_F32.pack(x))[0]
    except OverflowError:  # beyond the largest binary32: what a binary32 operation gives
        return math.copysign(float("inf"), x)


# R5.14's constants as the binary32 values the server and core use
_IV_HELD_WEIGHT = 1.0 / 64.0
_LOBE0 = _f32(SH_LOBE0)
_LOBE1 = _f32(SH_LOBE1)


def iv_irradiance(dims, origin, cell_size, cell, held, neighbours, p, n):
    """SPEC R5.14's lookup: E (W/m^2, r, g, b) at surface point p with normal
    n from an iv volume: ``dims``, ``origin``, ``cell_size`` its one level,
    ``cell(x, y, z)`` a voxel's 12 values, ``held(x, y, z)`` its index entry
    (non-zero: the voxel holds a surface), ``neighbours`` the description's
    iv_neighbours. Step by step in binary32 as techniques/iv/core/oracle_iv_reconstruct.c computes it
    (lpv_iv_irradiance; the sums of step 6 in double, as there)."""
    f32 = _f32
    # 1. a finite p, a unit-able n
    p = [f32(float(v)) for v in p]
    n = [f32(float(v)) for v in n]
    if not all(math.isfinite(v) for v in p + n):
        return (0.0, 0.0, 0.0)
    ln = f32(math.sqrt(f32(f32(f32(n[0] * n[0]) + f32(n[1] * n[1])) + f32(n[2] * n[2]))))
    if not (ln > f32(1e-8)) or ln == float("inf"):
        return (0.0, 0.0, 0.0)
    nh = [f32(v / ln) for v in n]
    s = f32(cell_size)
    o = [f32(v) for v in origin]
    # 2. half a voxel in front of the surface, the 8 voxel centres around it
    base, f = [0, 0, 0], [0.0, 0.0, 0.0]
    for a in range(3):
        q = f32(p[a] + f32(f32(0.5 * s) * nh[a]))
        u = f32(f32(f32(q - o[a]) / s) - 0.5)
        if not (-1.0 <= u < dims[a]):
            return (0.0, 0.0, 0.0)
        b = float(int(u // 1))
        base[a] = int(b)
        f[a] = f32(u - b)
    # 3. + 4. the corners by distance to q (ties: the lower number), the nearest `neighbours`
    d2 = []
    for c in range(8):
        acc = 0.0
        for a in range(3):
            e = f32(f[a] - ((c >> a) & 1))
            acc = f32(acc + f32(e * e))
        d2.append(acc)
    order = sorted(range(8), key=lambda c: (d2[c], c))
    neighbours = min(max(int(neighbours), 1), 8)
    idx, weight = [], []
    for c in order[:neighbours]:
        v = [base[a] + ((c >> a) & 1) for a in range(3)]
        if not all(0 <= v[a] < dims[a] for a in range(3)):
            continue
        # 5. trilinear weight x the cosine towards the voxel's centre, 1/64 for a voxel holding a surface
        t = 1.0
        for a in range(3):
            t = f32(t * (f[a] if (c >> a) & 1 else f32(1.0 - f[a])))
        d = [f32(f32(o[a] + f32(f32(v[a] + 0.5) * s)) - p[a]) for a in range(3)]
        ln2 = f32(math.sqrt(f32(f32(f32(d[0] * d[0]) + f32(d[1] * d[1])) + f32(d[2] * d[2]))))
        cosine = 0.0
        if ln2 > 0.0:
            c = [f32(nh[a] * f32(d[a] / ln2)) for a in range(3)]
            cosine = f32(f32(c[0] + c[1]) + c[2])
        w = f32(t * (cosine if cosine > 0.0 else 0.0))
        if held(v[0], v[1], v[2]):
            w = f32(w * _IV_HELD_WEIGHT)
        if not (w > 0.0):
            continue
        idx.append(v)
        weight.append(w)
    # 6. the blend, then the cosine lobe around -n (radiance: no / s^2)
    total = sum(weight)
    if not (total > 0.0):
        return (0.0, 0.0, 0.0)
    acc = [0.0] * 12
    for v, w in zip(idx, weight):
        vals = cell(v[0], v[1], v[2])
        for k in range(12):
            acc[k] += w * float(vals[k])
    lobe = (_LOBE0, f32(_LOBE1 * -nh[1]), f32(_LOBE1 * -nh[2]), f32(_LOBE1 * -nh[0]))
    e3 = []
    for ch in range(3):
        L = [f32(acc[4 * ch + k] / total) for k in range(4)]
        e3.append(f32(f32(f32(f32(L[0] * lobe[0]) + f32(L[1] * lobe[1])) + f32(L[2] * lobe[2])) + f32(L[3] * lobe[3])))
    # 7. made light as a whole colour: luminance y <= 0 gives 0; else y is
    # kept and, where the most negative channel m < 0, the chroma scales
    # by y / (y - 2 m)
    y = f32(f32(f32(e3[0] * f32(0.2126)) + f32(e3[1] * f32(0.7152))) + f32(e3[2] * f32(0.0722)))
    if not y > 0.0:
        return (0.0, 0.0, 0.0)
    m = min(e3)
    if m >= 0.0:
        return tuple(e3)
    s = f32(y / f32(y - f32(2.0 * m)))
    return tuple(f32(y + f32(f32(c - y) * s)) for c in e3)


class Cascade(object):
    """One cascade (level) of a volume (SPEC R5.6, R5.10): ``dims``,
    ``origin`` (m, lower corner), ``cell_size`` (m), ``values_per_cell`` and
    ``volumes`` (the description's volumes_per_level; 1 and 12 for R5.1's
    layout) and ``data``: ``volumes * cells * values_per_cell`` float32
    values, cell-major, x fastest (``index = x + nx * (y + ny * z)``); for
    R5.1's layout per cell r0..r3 g0..g3 b0..b3 in radiant intensity W/sr. A
    numpy array of shape (nz, ny, nx, values_per_cell) (one volume) or
    (volumes, nz, ny, nx, values_per_cell) when numpy is available, else a
    flat ``array('f')``. ``role`` is "cascade" or "far_field" (or
    "octree_level", R5.13, or "iv_voxels", R5.14: technique iv's voxels,
    radiance W/(m^2 sr) at their centres, which R5.7's ``irradiance`` and
    ``total_flux`` refuse; ``Volume.irradiance`` reads them by R5.14).
    """

    def __init__(self, dims, origin, cell_size, values, values_per_cell=12, volumes=1, role="cascade",
                 lookup_refusal=None):
        self.dims = tuple(int(v) for v in dims)
        self.origin = tuple(float(v) for v in origin)
        self.cell_size = float(cell_size)
        self.values_per_cell = int(values_per_cell)
        self.volumes = int(volumes)
        self.role = role
        self._lookup_refusal = lookup_refusal
        cells = self.dims[0] * self.dims[1] * self.dims[2]
        if len(values) != cells * self.values_per_cell * self.volumes:
            raise ProtocolError("cascade of %d values for %d cells x %d volumes x %d values" % (
                len(values), cells, self.volumes, self.values_per_cell))
        if _np is not None:
            shape = (self.dims[2], self.dims[1], self.dims[0], self.values_per_cell)
            values = values.reshape(shape if self.volumes == 1 else (self.volumes,) + shape)
        self.data = values

    def _check_lookup(self):
        if self._lookup_refusal:
            raise LayoutError(self._lookup_refusal)

    def contains(self, p):
        """Whether world point p lies inside this cascade's box."""
        for a in range(3):
            u = (p[a] - self.origin[a]) / self.cell_size
            if not (0.0 <= u <= self.dims[a]):
                return False
        return True

    def border_cells(self, p):
        """Distance from p to the box's border in this cascade's cells (the
        smallest over the six faces; negative outside)."""
        d = None
        for a in range(3):
            u = (p[a] - self.origin[a]) / self.cell_size
            m = min(u, self.dims[a] - u)
            d = m if d is None else min(d, m)
        return d

    @property
    def cells(self):
        return self.dims[0] * self.dims[1] * self.dims[2]

    def cell(self, x, y, z):
        """The 12 coefficients of cell (x, y, z) as a list."""
        self._check_lookup()
        if _np is not None:
            return [float(v) for v in self.data[z, y, x]]
        i = (x + self.dims[0] * (y + self.dims[1] * z)) * 12
        return list(self.data[i:i + 12])

    def _check_r57(self):
        self._check_lookup()
        if self.role == IV_VOXELS_ROLE:
            raise LayoutError("technique iv's voxels (role %r) hold radiance (%s) at their centres, not the intensity "
                              "per cell R5.7's lookup reads: use Volume.irradiance (SPEC R5.14)"
                              % (IV_VOXELS_ROLE, IV_UNITS))

    def total_flux(self):
        """Sum over cells of c0 * sqrt(4 pi) per channel, in W."""
        self._check_r57()
        k = (4.0 * 3.141592653589793) ** 0.5
        if _np is not None:
            d = self.data.reshape(-1, 12)
            return [float(d[:, 0].sum() * k), float(d[:, 4].sum() * k), float(d[:, 8].sum() * k)]
        r = g = b = 0.0
        for i in range(0, len(self.data), 12):
            r += self.data[i]
            g += self.data[i + 4]
            b += self.data[i + 8]
        return [r * k, g * k, b * k]

    def sh_at(self, p):
        """Trilinear interpolation of the 12 coefficients at world point p,
        between cell centres, clamped to the outermost centres (GL_CLAMP_TO_EDGE),
        as docs/propagation.md section 6. Returns None for a NaN coordinate."""
        i0, i1, f = [0, 0, 0], [0, 0, 0], [0.0, 0.0, 0.0]
        for a in range(3):
            u = (p[a] - self.origin[a]) / self.cell_size
            if u != u:
                return None
            n = self.dims[a]
            u = min(max(u, 0.5), n - 0.5) - 0.5
            base = float(int(u // 1))
            if base > n - 2:
                base = float(n - 2)
            if base < 0:
                base = 0.0
            i0[a] = int(base)
            i1[a] = i0[a] + 1 if i0[a] + 1 < n else i0[a]
            f[a] = u - base
        out = [0.0] * 12
        for corner in range(8):
            w = 1.0
            idx = [0, 0, 0]
            for a in range(3):
                if corner >> a & 1:
                    idx[a] = i1[a]
                    w *= f[a]
                else:
                    idx[a] = i0[a]
                    w *= 1.0 - f[a]
            if w == 0.0:
                continue
            c = self.cell(idx[0], idx[1], idx[2])
            for k in range(12):
                out[k] += w * c[k]
        return out

    def irradiance(self, p, n):
        """E(n) in W/m^2 (r, g, b) at surface point p with normal n from this
        cascade alone (propagation.md §6): sample half a cell in front of the
        surface, E = max(0, c . lobe(-n)) / s^2. Raises LayoutError for a
        volume whose values are not LOOKUP_VALUES in one volume per level (or
        are technique iv's voxels, SPEC R5.14)."""
        self._check_r57()
        ln = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) ** 0.5
        if not (ln > 1e-8) or ln == float("inf") or any(v != v for v in n):
            return (0.0, 0.0, 0.0)
        un = [v / ln for v in n]
        q = [p[a] + 0.5 * self.cell_size * un[a] for a in range(3)]
        c = self.sh_at(q)
        if c is None:
            return (0.0, 0.0, 0.0)
        lobe = (SH_LOBE0, -SH_LOBE1 * un[1], -SH_LOBE1 * un[2], -SH_LOBE1 * un[0])
        inv = 1.0 / (self.cell_size * self.cell_size)
        rgb = []
        for ch in range(3):
            d = sum(c[4 * ch + k] * lobe[k] for k in range(4))
            rgb.append(max(0.0, d * inv))
        return tuple(rgb)


class Volume(Cascade):
    """A decoded LPV (SPEC section 5) with every cascade (R5.6).

    ``cascades`` lists the ``Cascade`` objects, finest first. The volume's
    own ``dims``, ``origin``, ``cell_size``, ``data``, ``cell()`` and
    ``total_flux()`` are cascade 0's (the finest; the whole volume when there
    is one cascade); ``irradiance()`` blends the cascades as R5.7 (and the
    server's QUERY_IRRADIANCE) do. ``plan`` is the tick's plan (SPEC section
    8) or None. ``units`` are the values' units.

    Technique iv's volume (SPEC R5.14; ``iv`` true): one level of voxels
    holding the radiance arriving at their centres (``units`` W/(m^2 sr)),
    ``index`` one flag per voxel (1: it holds a surface) and
    ``iv_neighbours``; ``irradiance()`` is then R5.14's lookup
    (``iv_irradiance``).
    """

    def __init__(self, header, raw):
        self.header = header
        self.raw = raw  # the raw (decompressed, delta-resolved) bytes
        self.tick = header.get("tick")
        self.revision = header.get("revision")
        self.format = header.get("format")
        self.keyframe = bool(header.get("keyframe", True))
        self.base_tick = header.get("base_tick")
        self.plan = header.get("plan")
        grid = header.get("grid") or {}
        specs = header.get("cascades")
        if specs is None:  # a server before cascades: the grid is the volume
            specs = [dict(grid, cells=None)]
        if not isinstance(specs, list) or not 1 <= len(specs) <= MAX_CASCADES:
            raise ProtocolError("cascades: expected 1 to %d entries" % MAX_CASCADES)
        self.description = self._describe(header, specs)
        desc = self.description
        # SPEC R5.13: GET_VOLUME content "levels" describes an octree's levels
        # (the cascades then are level 0 alone); else the levels are the cascades
        octree = self._octree_levels(desc)
        self.iv = self._iv_levels(desc)
        self.iv_neighbours = desc.get("iv_neighbours") if self.iv else None
        self.units = desc.get("units") or header.get("units") or LPV_UNITS
        self.content = "levels" if octree else "merged"
        vpc, vpl = desc["values_per_cell"], desc["volumes_per_level"]
        self.values_per_cell, self.volumes_per_level = vpc, vpl
        self.technique, self.far_field = desc["technique"], desc["far_field"]
        refusal = None
        if octree:
            refusal = ("volume of content \"levels\" (technique %r: its %d octree levels and index volume) is not "
                       "the merged grid the lookup reads (SPEC R5.7, R5.13): ask get_volume(content=\"merged\")" % (
                           desc["technique"], len(desc["levels"])))
        elif self.iv:
            pass  # R5.14: read by its own lookup (Volume.irradiance)
        elif vpl != 1 or desc["index"] is not None or self.units != LPV_UNITS or (
                desc["values"] is not None and tuple(desc["values"]) != LOOKUP_VALUES):
            refusal = ("volume layout of technique %r (layout_version %d, %d values per cell %s, %d volumes per "
                       "level%s, units %s) is not the 12 SH values %s in %s in one volume per level, the only layout "
                       "this client's lookup reads (SPEC R5.7, R5.11)" % (
                           desc["technique"], desc["layout_version"], vpc, desc["values"], vpl,
                           ", with an index volume" if desc["index"] is not None else "", self.units,
                           list(LOOKUP_VALUES), LPV_UNITS))
        self.lookup_refusal = refusal
        size = 2 if self.format == "fp16" else 4
        index = desc["index"]
        values_end = int(index["raw_offset"]) if index is not None else len(raw)
        values = _floats(raw[:values_end], self.format)
        self.index = None
        if index is not None:  # R5.12: little-endian u32 after the levels' values
            ib = raw[values_end:values_end + int(index["raw_length"])]
            self.index = array.array("I", struct.unpack("<%dI" % (len(ib) // 4), ib))
        self.cascades = []
        first = 0
        for k, c in enumerate(desc["levels"] if octree else specs):
            dims = [int(v) for v in c.get("dims", (0, 0, 0))]
            if len(dims) != 3 or min(dims) < 1:
                raise ProtocolError("cascades[%d].dims: expected 3 integers >= 1" % k)
            cells = dims[0] * dims[1] * dims[2]
            if c.get("cells") is not None and int(c["cells"]) != cells:
                raise ProtocolError("cascades[%d].cells: %r, its dims give %d" % (k, c["cells"], cells))
            cs = float(c.get("cell_size", 0.0))
            if not cs > 0.0:
                raise ProtocolError("cascades[%d].cell_size: expected a positive number" % k)
            n = cells * vpc * vpl
            if first + n > len(values):
                raise ProtocolError("volume of %d values, the cascades need more" % len(values))
            self.cascades.append(Cascade(dims, c.get("origin", (0.0, 0.0, 0.0)), cs, values[first:first + n],
                                         vpc, vpl, desc["levels"][k].get("role", "cascade"), refusal))
            first += n
        if first != len(values):
            raise ProtocolError("volume of %d values (%d bytes of %s) for %d values as described" % (
                len(values), len(values) * size, self.format, first))
        # the description's levels: every octree level for content "levels",
        # else the cascades; the cascades are what the legacy keys describe
        self.levels = list(self.cascades)
        if octree:
            self.cascades = self.cascades[:1]
        c0 = self.cascades[0]
        if grid and (tuple(int(v) for v in grid.get("dims", ())) != c0.dims
                     or abs(float(grid.get("cell_size", 0.0)) - c0.cell_size) > 1e-9 * c0.cell_size):
            raise ProtocolError("grid: differs from cascades[0]")
        self.dims, self.origin, self.cell_size, self.data = c0.dims, c0.origin, c0.cell_size, c0.data
        self.role, self.values_per_cell, self.volumes = c0.role, c0.values_per_cell, c0.volumes
        self._lookup_refusal = refusal

    @staticmethod
    def _describe(header, specs):
        """The header's description (SPEC R5.9 - R5.12), checked; or, from a
        server without one, R5.1's layout from the legacy keys (layout_version
        0, values None: named by the "layout" string)."""
        d = header.get("volume")
        if d is None:
            return {"layout_version": 0, "technique": "", "far_field": False, "volumes_per_level": 1,
                    "values_per_cell": 12, "values": None, "units": header.get("units"), "index": None,
                    "levels": [dict(c, role="cascade") for c in specs]}
        if not isinstance(d, dict):
            raise ProtocolError("volume: expected an object")
        if d.get("layout_version") != VOLUME_LAYOUT_VERSION:
            raise ProtocolError("volume.layout_version: %r is not a layout this client reads (it reads %d)" % (
                d.get("layout_version"), VOLUME_LAYOUT_VERSION))
        vpc, vpl = d.get("values_per_cell"), d.get("volumes_per_level")
        if not isinstance(vpc, int) or vpc < 1:
            raise ProtocolError("volume.values_per_cell: expected an integer >= 1, got %r" % (vpc,))
        if not isinstance(vpl, int) or vpl < 1:
            raise ProtocolError("volume.volumes_per_level: expected an integer >= 1, got %r" % (vpl,))
        vals = d.get("values")
        if not isinstance(vals, list) or len(vals) != vpc or len(set(vals)) != vpc:
            raise ProtocolError("volume.values: expected %d distinct names (values_per_cell), got %r" % (vpc, vals))
        levels = d.get("levels")
        if Volume._octree_levels(d):
            Volume._check_octree_levels(d, specs)
            return d
        if Volume._iv_levels(d):
            Volume._check_iv_levels(d, specs, header)
            return d
        if not isinstance(levels, list) or len(levels) != len(specs):
            raise ProtocolError("volume.levels: expected %d levels (one per cascade)" % len(specs))
        for k, (lv, c) in enumerate(zip(levels, specs)):
            if any(lv.get(key) != c.get(key) for key in ("dims", "origin", "cell_size", "cells")):
                raise ProtocolError("volume.levels[%d]: differs from cascades[%d]" % (k, k))
        if d.get("index") is not None:
            ix = d["index"]
            if not isinstance(ix, dict) or not isinstance(ix.get("raw_offset"), int) \
                    or not isinstance(ix.get("raw_length"), int):
                raise ProtocolError("volume.index: expected null or an object with raw_offset and raw_length")
        return d
    @staticmethod
    def _octree_levels(d):
        """Whether description d's levels are an octree's (SPEC R5.13)."""
        levels = d.get("levels") if isinstance(d, dict) else None
        return isinstance(levels, list) and bool(levels) and isinstance(levels[0], dict) \
            and levels[0].get("role") == OCTREE_LEVEL_ROLE

    @staticmethod
    def _iv_levels(d):
        """Whether description d's levels are technique iv's voxels (SPEC R5.14)."""
        levels = d.get("levels") if isinstance(d, dict) else None
        return isinstance(levels, list) and bool(levels) and isinstance(levels[0], dict) \
            and levels[0].get("role") == IV_VOXELS_ROLE

    @staticmethod
    def _check_iv_levels(d, specs, header):
        """R5.14: one cascade and one "iv_voxels" level equal to it, far field
        false, the 12 SH values in one volume, radiance units, the index over
        level 0 (one u32 per voxel) and iv_neighbours in 1..8."""
        levels = d["levels"]
        if len(specs) != 1 or len(levels) != 1:
            raise ProtocolError("volume.levels: %d levels over %d cascades, but %r is exactly one level over one "
                                "cascade (SPEC R5.14)" % (len(levels), len(specs), IV_VOXELS_ROLE))
        c0, lv = specs[0], levels[0]
        if any(lv.get(key) != c0.get(key) for key in ("dims", "origin", "cell_size", "cells")):
            raise ProtocolError("volume.levels[0]: differs from cascades[0]")
        if d.get("far_field") is not False:
            raise ProtocolError("volume.far_field: %r with %r levels, expected false" % (d.get("far_field"),
                                                                                         IV_VOXELS_ROLE))
        if d.get("volumes_per_level") != 1 or tuple(d.get("values") or ()) != LOOKUP_VALUES:
            raise ProtocolError("volume.values: %r levels hold the 12 SH values %s in one volume (got %r, %r "
                                "volumes)" % (IV_VOXELS_ROLE, list(LOOKUP_VALUES), d.get("values"),
                                              d.get("volumes_per_level")))
        if d.get("units") != IV_UNITS or header.get("units") != IV_UNITS:
            raise ProtocolError("volume.units: %r (header %r) with %r levels, expected %r" % (
                d.get("units"), header.get("units"), IV_VOXELS_ROLE, IV_UNITS))
        dims = c0.get("dims")
        cells = dims[0] * dims[1] * dims[2] if isinstance(dims, list) and len(dims) == 3 else None
        ix = d.get("index")
        if not isinstance(ix, dict) or ix.get("level") != 0 or ix.get("dims") != dims \
                or ix.get("values_per_cell") != 1 or ix.get("value_type") != "u32" \
                or not isinstance(ix.get("raw_offset"), int) or ix.get("raw_length") != (cells or 0) * 4:
            raise ProtocolError("volume.index: %r levels need the index over level 0 (level 0, dims %r, "
                                "values_per_cell 1, u32)" % (IV_VOXELS_ROLE, dims))
        nb = d.get("iv_neighbours")
        if not isinstance(nb, int) or isinstance(nb, bool) or not 1 <= nb <= 8:
            raise ProtocolError("volume.iv_neighbours: %r, expected an integer in [1, 8] with %r levels"
                                % (nb, IV_VOXELS_ROLE))

    @staticmethod
    def _check_octree_levels(d, specs):
        """R5.13: one cascade (level 0), l = log2(n) + 1 levels, level i at
        level 0's origin with dims n >> i and cell size 2^i x level 0's, and
        the index over level 0 (one u32 per cell)."""
        levels = d["levels"]
        if len(specs) != 1:
            raise ProtocolError("cascades: %d entries, but octree levels need exactly one, level 0" % len(specs))
        c0 = specs[0]
        n = c0.get("dims", [0])[0]
        if list(c0.get("dims", ())) != [n, n, n] or not isinstance(n, int) or n < 1 or n & (n - 1):
            raise ProtocolError("volume.levels: octree levels over level 0 of dims %r (not a cube of a power of two)"
                                % (c0.get("dims"),))
        count = n.bit_length()
        if len(levels) != count:
            raise ProtocolError("volume.levels: %d octree levels, an octree over %d^3 cells has %d" % (
                len(levels), n, count))
        if d.get("far_field"):
            raise ProtocolError("volume.far_field: true with octree levels")
        for i, lv in enumerate(levels):
            m = n >> i
            cs = float(c0.get("cell_size", 0.0)) * (1 << i)
            if not isinstance(lv, dict) or lv.get("role") != OCTREE_LEVEL_ROLE or lv.get("dims") != [m, m, m] \
                    or lv.get("cells") != m * m * m or lv.get("origin") != c0.get("origin") \
                    or abs(float(lv.get("cell_size", 0.0)) - cs) > 1e-9 * cs:
                raise ProtocolError("volume.levels[%d]: not octree level %d (role %r, level 0's origin, dims "
                                    "n >> %d, cell size 2^%d x level 0's)" % (i, i, OCTREE_LEVEL_ROLE, i, i))
        ix = d.get("index")
        if not isinstance(ix, dict) or ix.get("level") != 0 or ix.get("dims") != [n, n, n] \
                or ix.get("values_per_cell") != 1 or not isinstance(ix.get("raw_offset"), int) \
                or ix.get("raw_length") != n * n * n * 4:
            raise ProtocolError("volume.index: octree levels need the index over level 0 (level 0, dims %r, "
                                "values_per_cell 1, %d bytes)" % ([n, n, n], n * n * n * 4))

    def irradiance(self, p, n):
        """E(n) in W/m^2 (r, g, b) at surface point p with normal n, computed
        locally as the server's QUERY_IRRADIANCE (SPEC R5.7): the finest
        cascade containing p, blended towards the next coarser one within the
        last 3 cells of its border, w = clamp((d - 1) / 2, 0, 1); each
        cascade's lookup as propagation.md §6. Technique iv's voxels (``iv``):
        R5.14's lookup instead (``iv_irradiance`` with the index and
        iv_neighbours). Raises LayoutError (naming the layout) for a volume
        neither lookup reads."""
        self._check_lookup()
        if self.iv:
            nx, ny = self.dims[0], self.dims[1]
            index = self.index
            return iv_irradiance(self.dims, self.origin, self.cell_size, self.cell,
                                 lambda x, y, z: index[x + nx * (y + ny * z)], self.iv_neighbours, p, n)
        cs = self.cascades
        k = next((i for i, c in enumerate(cs) if c.contains(p)), len(cs) - 1)
        fine = Cascade.irradiance(cs[k], p, n)
        if k + 1 >= len(cs) or not cs[k + 1].contains(p):
            return fine
        d = cs[k].border_cells(p)
        w = min(max((d - 1.0) / 2.0, 0.0), 1.0)
        if w >= 1.0:
            return fine
        coarse = Cascade.irradiance(cs[k + 1], p, n)
        return tuple(w * f + (1.0 - w) * c for f, c in zip(fine, coarse))


class Frame(object):
    """A frame (SPEC section 6): ``header`` and ``data`` (bytes: rgba8 pixels,
    or the complete PNG / EXR file)."""

    def __init__(self, header, data):
        self.header = header
        self.data = data
        self.width = header.get("width")
        self.height = header.get("height")
        self.format = header.get("format")
        self.tick = header.get("tick")
        self.revision = header.get("revision")
        self.plan = header.get("plan")  # the tick's plan (SPEC section 8) or None

    def save(self, path):
        with open(path, "wb") as f:
            f.write(self.data)


class Client(object):
    """One connection (one session) to an lpvd daemon.

    ``address``: a Unix socket path, ``unix:PATH``, ``HOST:PORT`` or
    ``tcp:HOST:PORT``; default: the daemon's default socket. The constructor
    connects and sends HELLO (with ``token`` when given); ``hello_reply``
    holds the server's answer. Every request method returns the reply body
    (a dict) or raises ``LpvdError`` with the SPEC's error code and name.
    """

    def __init__(self, address=None, token=None, client_name="lpvd_client.py", timeout=None,
                 connect=True):
        self.address = address or default_address()
        self.token = token
        self.client_name = client_name
        self.timeout = timeout
        self.sock = None
        self.hello_reply = None
        self._next_id = 1
        self._stream_queue = []      # (type, header, attachment) received while waiting for replies
        self._acked = {}             # tick -> raw bytes of volumes we acknowledged (delta bases)
        self._acked_order = []
        self.keep_acked = 8
        self.closed_by_server = None  # "BYE" or an LpvdError when the server closed us
        if connect:
            self.connect()

    # -- connection -------------------------------------------------------

    def connect(self):
        kind, addr = _parse_address(self.address)
        if kind == "unix":
            s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        else:
            infos = socket.getaddrinfo(addr[0], addr[1], 0, socket.SOCK_STREAM)
            s = socket.socket(infos[0][0], socket.SOCK_STREAM)
            addr = infos[0][4]
        if self.timeout is not None:
            s.settimeout(self.timeout)
        try:
            s.connect(addr)
        except OSError:
            s.close()
            raise
        if kind == "tcp":
            s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.sock = s
        self.hello_reply = self.hello()
        return self.hello_reply

    def close(self):
        if self.sock is not None:
            try:
                self.sock.close()
            finally:
                self.sock = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        if self.sock is not None and exc[0] is None:
            try:
                self.bye()
            except (LpvdError, ProtocolError, OSError):
                pass
        self.close()
        return False

    # -- framing ----------------------------------------------------------

    def _recv_exact(self, n):
        buf = bytearray()
        while len(buf) < n:
            chunk = self.sock.recv(min(n - len(buf), 1 << 20))
            if not chunk:
                raise ProtocolError("connection closed by the server (%d of %d bytes)" % (len(buf), n))
            buf += chunk
        return bytes(buf)

    def send_frame(self, mtype, body=None, attachment=b"", request_id=None):
        """Send one frame; returns its request_id."""
        if self.sock is None:
            raise ProtocolError("not connected")
        if request_id is None:
            request_id = self._next_id
            self._next_id = (self._next_id % 0xFFFFFFFF) + 1
        js = json.dumps(body if body is not None else {}, separators=(",", ":")).encode("utf-8")
        att = bytes(attachment) if attachment else b""
        self.sock.sendall(HEADER.pack(MAGIC, VERSION, mtype, request_id, 0, len(js), len(att)) + js + att)
        return request_id

    def recv_frame(self):
        """Receive one frame: (type, request_id, body dict, attachment bytes)."""
        if self.sock is None:
            raise ProtocolError("not connected")
        magic, version, mtype, rid, flags, jlen, alen = HEADER.unpack(self._recv_exact(HEADER.size))
        if magic != MAGIC:
            raise ProtocolError("bad magic %r from the server" % magic)
        if version != VERSION:
            raise ProtocolError("server speaks version %d" % version)
        if jlen < 2:
            raise ProtocolError("json_length %d < 2" % jlen)
        raw = self._recv_exact(jlen)
        att = self._recv_exact(alen) if alen else b""
        try:
            body = json.loads(raw.decode("utf-8"))
        except ValueError as e:
            raise ProtocolError("bad JSON body from the server: %s" % e)
        if not isinstance(body, dict):
            raise ProtocolError("JSON body is not an object")
        return mtype, rid, body, att

    @staticmethod
    def _error(body):
        code = body.get("code", 0)
        return LpvdError(code, body.get("name", ERROR_NAMES.get(code, "ERROR")),
                         body.get("message", ""), body)

    def request(self, mtype, body=None, attachment=b""):
        """Send a request and wait for its reply: (body, attachment).
        Stream messages arriving meanwhile are queued for ``next_message``."""
        rid = self.send_frame(mtype, body, attachment)
        while True:
            rtype, rrid, rbody, ratt = self.recv_frame()
            if rid and rrid == rid and rtype == (mtype | REPLY_BIT):
                return rbody, ratt
            if rtype == MSG["ERROR"] and (rrid == rid or rrid == 0):
                err = self._error(rbody)
                if rrid == 0:
                    self.closed_by_server = err
                    self.close()
                elif err.code in (1, 3, 4, 8, 15) or (err.code == 2 and mtype != MSG["HELLO"]):
                    # errors that close the connection (SPEC R3.4; a HELLO's
                    # BAD_VERSION leaves it open, R4.1)
                    self.close()
                raise err
            if rtype in (MSG["VOLUME"], MSG["FRAME"]):
                self._stream_queue.append((rtype, rbody, ratt))
                continue
            if rtype == SERVER_BYE and rrid == 0:
                self.closed_by_server = "BYE"
                self.close()
                raise ProtocolError("the server said BYE")
            raise ProtocolError("unexpected frame type 0x%04x request_id %d while waiting for 0x%04x #%d"
                                % (rtype, rrid, mtype | REPLY_BIT, rid))

    # -- requests (SPEC section 4) ---------------------------------------

    def hello(self, version=VERSION):
        body = {"version": version, "client": self.client_name}
        if self.token is not None:
            body["token"] = self.token
        return self.request(MSG["HELLO"], body)[0]

    def scene_load_file(self, path):
        """SCENE_LOAD by path (resolved under the server's --scene-root)."""
        return self.request(MSG["SCENE_LOAD"], {"path": path})[0]

    def scene_load_glb(self, glb):
        """SCENE_LOAD with the .glb bytes as attachment."""
        return self.request(MSG["SCENE_LOAD"], {}, glb)[0]

    def scene_update(self, nodes=None, materials=None, animation_time=None, animation=None):
        """SCENE_UPDATE: node transforms, material edits, and/or the scene posed at animation_time seconds
        of its animation (a name or index; None: every animation) (SPEC R4.4c)."""
        body = {}
        if nodes is not None:
            body["nodes"] = list(nodes)
        if materials is not None:
            body["materials"] = list(materials)
        if animation_time is not None:
            body["animation"] = {"time": float(animation_time)}
            if animation is not None:
                body["animation"]["name"] = animation
        return self.request(MSG["SCENE_UPDATE"], body)[0]

    def light_set(self, id, type, intensity, color=None, position=None, direction=None,
                  range=None, inner_cone=None, outer_cone=None):
        body = {"id": id, "type": type, "intensity": intensity}
        for k, v in (("color", color), ("position", position), ("direction", direction),
                     ("range", range), ("inner_cone", inner_cone), ("outer_cone", outer_cone)):
            if v is not None:
                body[k] = list(v) if isinstance(v, (tuple, list)) else v
        return self.request(MSG["LIGHT_SET"], body)[0]

    def light_remove(self, id):
        return self.request(MSG["LIGHT_REMOVE"], {"id": id})[0]

    def camera_set(self, eye=None, target=None, up=None, fov_deg=None, width=None, height=None,
                   camera=None):
        """An explicit camera (eye, target, ...) or ``camera=`` a scene camera's index or name."""
        if camera is not None:
            body = {"camera": camera}
        else:
            if eye is None or target is None:
                raise ValueError("camera_set needs eye and target, or camera=")
            body = {"eye": list(eye), "target": list(target)}
            for k, v in (("up", up), ("fov_deg", fov_deg), ("width", width), ("height", height)):
                if v is not None:
                    body[k] = list(v) if isinstance(v, (tuple, list)) else v
        return self.request(MSG["CAMERA_SET"], body)[0]

    @property
    def knobs(self):
        """CONFIG's knobs as the server describes them in HELLO (SPEC R4.12):
        name -> {"type": "int" | "number" | "bool", "min", "max",
        "min_exclusive", "default", "default_text", "unit", "note", "help"}."""
        return {k["name"]: k for k in (self.hello_reply or {}).get("knobs", [])}

    @property
    def presets(self):
        """The preset names the server offers (HELLO "presets")."""
        return list((self.hello_reply or {}).get("presets", []))

    @property
    def techniques(self):
        """The GI techniques the server offers (HELLO "techniques", SPEC R4.14)."""
        return list((self.hello_reply or {}).get("techniques", []))

    @staticmethod
    def knob_value(knob, v):
        """v checked against a knob's description and typed for CONFIG:
        bools take True / False or "on" / "off"; ints an integral number;
        numbers a number in range. Raises ValueError naming the knob."""
        name, kind = knob["name"], knob["type"]
        if kind == "bool":
            if v in ("on", "off"):
                return v == "on"
            if isinstance(v, bool):
                return v
            raise ValueError("%s: expected on or off, got %r" % (name, v))
        if isinstance(v, bool) or not isinstance(v, (int, float)) or v != v:
            raise ValueError("%s: expected a number, got %r" % (name, v))
        lo, hi = knob["min"], knob["max"]
        if kind == "int" and v != int(v):
            raise ValueError("%s: expected an integer, got %r" % (name, v))
        if v > hi or v < lo or (knob.get("min_exclusive") and v == lo):
            raise ValueError("%s: %r is outside %s%s..%s%s" % (name, v, "(" if knob.get("min_exclusive") else "[",
                                                               lo, hi, "]"))
        return int(v) if kind == "int" else v

    def config(self, **settings):
        """CONFIG: technique (one of ``techniques``), preset (one of ``presets``), grid, bounds, tick_rate_hz and
        any knob the server describes (``knobs``; SPEC R4.12). A knob's value is
        checked against the description before sending. A preset sets grid,
        iterations, rsm_size and occlusion; the other fields given override it.
        Returns {"revision", "config": {...}}."""
        knobs = self.knobs
        body = {}
        for k, v in settings.items():
            if v is None:
                continue
            if k in knobs:
                v = self.knob_value(knobs[k], v)
            body[k] = list(v) if isinstance(v, tuple) else v
        return self.request(MSG["CONFIG"], body)[0]

    def tick(self):
        return self.request(MSG["TICK"], {})[0]

    def subscribe(self, stream="volume", format=None, compression=None, delta=None):
        body = {"stream": stream}
        if stream == "volume":
            body["format"] = format or "fp32"
            body["compression"] = compression or _default_compression()
            body["delta"] = True if delta is None else bool(delta)
        else:
            if format is not None:
                body["format"] = format
            body["compression"] = compression or _default_compression()
            if delta is not None:
                body["delta"] = bool(delta)
        return self.request(MSG["SUBSCRIBE"], body)[0]

    def unsubscribe(self, stream="volume"):
        return self.request(MSG["UNSUBSCRIBE"], {"stream": stream})[0]

    def get_volume(self, format="fp32", compression=None, content=None):
        """GET_VOLUME, decoded to a ``Volume`` (a keyframe). content: "merged"
        (None: the server's default, the merged volume) or "levels" (SPEC
        R5.13: an octree technique's levels, ``Volume.levels``, and its index
        volume, ``Volume.index``). Technique iv's volume (SPEC R5.14) comes
        as ``Volume.iv``, its occupancy as ``Volume.index``."""
        body = {"format": format, "compression": compression or _default_compression()}
        if content is not None:
            body["content"] = content
        hdr, att = self.request(MSG["GET_VOLUME"], body)
        return self._decode_volume(hdr, att, ack=False)

    def get_frame(self, format="rgba8", compression=None, terms="full", exposure=None, transparent=None):
        """GET_FRAME -> ``Frame`` (rgba8 pixels are decompressed). terms:
        "full", "indirect", "direct" or "ao" (ambient occlusion, a linear
        fraction, 1 = open; technique iv with iv_ao on only, SPEC R6.5).
        exposure: "auto" or an EV number (rgba8/png; None: the server's
        default, auto); transparent: background alpha 0 (SPEC R6.4)."""
        body = {"format": format, "terms": terms}
        if exposure is not None:
            body["exposure"] = exposure
        if transparent is not None:
            body["transparent"] = bool(transparent)
        if format == "rgba8":
            body["compression"] = compression or _default_compression()
        elif compression is not None:
            body["compression"] = compression
        hdr, att = self.request(MSG["GET_FRAME"], body)
        return self._decode_frame(hdr, att)

    def query_irradiance(self, points, normals):
        """QUERY_IRRADIANCE for surface points and normals (sequences of 3
        floats, or numpy (n, 3) arrays). Returns a numpy (n, 3) float32 array
        of W/m^2, or a list of (r, g, b) tuples without numpy."""
        n = len(points)
        if len(normals) != n:
            raise ValueError("%d points but %d normals" % (n, len(normals)))
        if _np is not None:
            pn = _np.empty((n, 6), dtype="<f4")
            if n:
                pn[:, 0:3] = _np.asarray(points, dtype=_np.float32).reshape(n, 3)
                pn[:, 3:6] = _np.asarray(normals, dtype=_np.float32).reshape(n, 3)
            att = pn.tobytes()
        else:
            flat = []
            for p, q in zip(points, normals):
                flat.extend((p[0], p[1], p[2], q[0], q[1], q[2]))
            att = struct.pack("<%df" % (6 * n), *flat)
        hdr, ratt = self.request(MSG["QUERY_IRRADIANCE"], {"count": n}, att)
        if len(ratt) != 12 * n:
            raise ProtocolError("QUERY_IRRADIANCE answered %d bytes for %d points" % (len(ratt), n))
        self.last_query = hdr
        if _np is not None:
            return _np.frombuffer(ratt, dtype="<f4").reshape(n, 3).copy()
        v = struct.unpack("<%df" % (3 * n), ratt)
        return [tuple(v[3 * i:3 * i + 3]) for i in range(n)]

    def stats(self):
        return self.request(MSG["STATS"], {})[0]

    def bye(self):
        """BYE: the server replies and closes; the socket is closed here too."""
        try:
            return self.request(MSG["BYE"], {})[0]
        finally:
            self.close()

    def ack(self, tick, stream="volume"):
        """ACK a volume (no reply): the server may then send XOR deltas against it."""
        self.send_frame(MSG["ACK"], {"stream": stream, "tick": int(tick)})

    # -- streams ----------------------------------------------------------

    def _remember(self, tick, raw):
        if tick in self._acked:
            return
        self._acked[tick] = raw
        self._acked_order.append(tick)
        while len(self._acked_order) > self.keep_acked:
            self._acked.pop(self._acked_order.pop(0), None)

    def _decode_volume(self, hdr, att, ack):
        raw = _decompress(att, hdr.get("compression", "none"), hdr.get("raw_length", len(att)))
        if "raw_length" in hdr and len(raw) != hdr["raw_length"]:
            raise ProtocolError("volume of %d bytes, header says raw_length %d" % (len(raw), hdr["raw_length"]))
        if not hdr.get("keyframe", True):
            base = hdr.get("base_tick")
            if base not in self._acked:
                raise ProtocolError("delta against tick %r which this client does not hold" % (base,))
            raw = _xor(raw, self._acked[base])
        vol = Volume(hdr, raw)
        if ack and vol.tick is not None:
            self._remember(vol.tick, raw)
            self.ack(vol.tick)
        return vol

    def _decode_frame(self, hdr, att):
        data = att
        if hdr.get("format") == "rgba8":
            data = _decompress(att, hdr.get("compression", "none"), hdr.get("raw_length", len(att)))
        return Frame(hdr, bytes(data))

    def next_message(self, ack=True):
        """Wait for the next stream message (after SUBSCRIBE) and return a
        ``Volume`` or ``Frame``. XOR deltas are undone against the volumes
        this client acknowledged; each volume is acknowledged (ACK) unless
        ``ack`` is False. Returns None when the server said BYE."""
        if self._stream_queue:
            rtype, body, att = self._stream_queue.pop(0)
        else:
            while True:
                rtype, rid, body, att = self.recv_frame()
                if rtype in (MSG["VOLUME"], MSG["FRAME"]):
                    break
                if rtype == SERVER_BYE:
                    self.closed_by_server = "BYE"
                    self.close()
                    return None
                if rtype == MSG["ERROR"]:
                    err = self._error(body)
                    if err.name == "SHUTTING_DOWN":
                        self.closed_by_server = err
                        self.close()
                    raise err
                raise ProtocolError("unexpected frame type 0x%04x (request_id %d) in the stream" % (rtype, rid))
        if rtype == MSG["VOLUME"]:
            return self._decode_volume(body, att, ack)
        return self._decode_frame(body, att)

    def stream(self, count=None, ack=True):
        """Iterate over stream messages (``count`` of them, or until BYE)."""
        n = 0
        while count is None or n < count:
            m = self.next_message(ack=ack)
            if m is None:
                return
            yield m
            n += 1


# -- self-test -------------------------------------------------------------

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


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
