"""lpvd_volume.py - volumes of the lpvd Python client: decoding a VOLUME or
GET_VOLUME reply's values (fp16/fp32, XOR deltas, compression "shq"'s
quantised SH and the bound it holds (SPEC R5.16), the layout description)
into ``Volume`` and ``Cascade`` objects (and, for GET_VOLUME content
"visibility", the probes' ``Visibility``), and their local lookups (SPEC
R5.7, R5.14's ``iv_irradiance`` for technique iv and R5.15's
``probes_irradiance`` for technique probes' visibility).

Standard library only (array, math, struct, sys); numpy is used when it is
importable (values then come back as float32 arrays). One of the modules of
the client; import ``lpvd_client``, which re-exports every name.

The protocol is protocol/SPEC.md; section numbers below refer to it.
"""

import array
import math
import struct
import sys

try:  # optional
    import numpy as _np
except ImportError:  # pragma: no cover - depends on the machine
    _np = None

from lpvd_protocol import ProtocolError, _zstd_decompress

HAVE_NUMPY = _np is not None

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
PROBES_TECHNIQUE = "probes"  # ray-traced irradiance probes (SPEC R5.15): an LPV's layout, and on request visibility
VISIBILITY_CONTENT = "visibility"  # GET_VOLUME content that adds the probes' visibility block (SPEC R5.15)
VISIBILITY_VALUE_TYPE = "f32"  # the visibility's values, whatever the volume's format (SPEC R5.15)
MAX_IRRADIANCE_SIDE = 16  # the sides of a probe's two octahedral maps (SPEC R5.15: I in 1..16, D in 1..32)
MAX_DISTANCE_SIDE = 32
# The values, in order, that this client's lookup (Cascade.irradiance: the
# cosine lobe on SH bands 0-1 per channel) reads; a volume whose description
# names other values is decoded but not looked up (SPEC R5.11).
LOOKUP_VALUES = tuple("%s.%s" % (ch, y) for ch in "rgb" for y in ("Y00", "Y1-1", "Y10", "Y11"))


class LayoutError(ValueError):
    """A lookup on a volume whose described layout (SPEC R5.11) it does not read;
    the message names the layout."""


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


def _is_int(v):
    """A JSON integer (not a bool, not 4.0)."""
    return isinstance(v, int) and not isinstance(v, bool)


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


# -- quantised SH, compression "shq" (SPEC R5.16) ----------------------------
#
# The attachment is one zstd frame whose content is "SHQ1", flags, the counts,
# a delta's bit map of the cells sent, one exponent per cell sent, a delta's
# mode per cell sent (0: the mantissas are the values' steps, 1: the change
# from the base's cell in those steps), the 12 zigzag mantissas in byte
# planes, then the bytes after the values (an index). A keyframe with flag bit 1
# (predicted) holds each cell's mantissas as their change from the previous
# cell's, scaled to the cell's step (_shq_predict). protocol/volume_shq.c's lpvp_shq_decode is the normative decoder;
# this one rebuilds the same fp32 bytes, bit for bit, with numpy or without.

SHQ_COMPRESSION = "shq"
SHQ_BOUND_MIN, SHQ_BOUND_MAX, SHQ_BOUND_DEFAULT = 0.001, 0.25, 0.01  # HELLO's volume_codecs.error_bound
SHQ_MAGIC = b"SHQ1"
_SHQ_HEAD = struct.Struct("<4sIQQQ")  # magic, flags (bit 0: keyframe), C cells, S cells sent, X bytes after
_SHQ_FLAG_KEY = 1
_SHQ_FLAG_PREDICTED = 2   # with bit 0 only: the mantissas are residuals of the previous cell's prediction
_SHQ_PREDICT_SHIFT_MAX = 15  # exponents farther apart: no prediction
_SHQ_ZERO_EXP = -128      # a cell sent as zero
_SHQ_CELL_BYTES = 48      # R5.1's 12 fp32 values
_SHQ_SENT_BYTES = 25      # per cell a keyframe sends: its exponent and 12 two-byte mantissas
_SHQ_SENT_BYTES_DELTA = 26  # per cell a delta sends: its mode too
_SHQ_ABSOLUTE, _SHQ_RELATIVE = 0, 1  # a delta's modes
_SHQ_VALUE_LIMIT = _f32(1e30)  # the server clamps exact values beyond it (binary32 1e30f; NaN is 0) before coding
_SHQ_TINY = 1e-30         # a cell of smaller magnitude is held as zero
_F32_OVERFLOW = 2.0 ** 128  # q x 2^x at or above it is no binary32: it rounds to infinity, as ldexpf does
_SHQ_FLAG_BLOCKS = 4      # a delta only: blocks move the client's cells before the cells sent
_SHQ_MAX_REGIONS = 16
_SHQ_BLOCK_EDGE_MAX = 64
_SHQ_BLOCK_EXP_MAX = 100  # a block's d x 2^x stays a binary32 value
_SHQ_REGION = struct.Struct("<QIII")  # first cell, nx, ny, nz


def shq_error_bound(header):
    """The error bound of an "shq" volume header, checked: R5.16's header says
    "format": "fp32" (shq decodes into what an fp32 message carries) and an
    "error_bound" number in [SHQ_BOUND_MIN, SHQ_BOUND_MAX]; anything else is
    a ProtocolError naming the key."""
    if header.get("format") != "fp32":
        raise ProtocolError("format: %r with compression \"shq\", which decodes to \"fp32\" (SPEC R5.16)"
                            % (header.get("format"),))
    e = header.get("error_bound")
    if isinstance(e, bool) or not isinstance(e, (int, float)) or not SHQ_BOUND_MIN <= e <= SHQ_BOUND_MAX:
        raise ProtocolError("error_bound: %r with compression \"shq\", expected a number in [%g, %g] (SPEC R5.16)"
                            % (e, SHQ_BOUND_MIN, SHQ_BOUND_MAX))
    return float(e)


def shq_cells(header):
    """(C, X) of an "shq" volume header: C the cells of its values (the raw
    volume up to the index, R5.12, in cells of R5.1's 12 fp32 values) and X
    the bytes after them. shq codes the merged volume only: a description of
    other values per cell, an octree's levels or the probes' visibility is a
    ProtocolError."""
    raw_length = header.get("raw_length")
    if not _is_int(raw_length) or raw_length < 0:
        raise ProtocolError("raw_length: %r, expected an integer >= 0" % (raw_length,))
    d = header.get("volume")
    values = raw_length
    if d is not None:  # an older server's header without a description: R5.1's layout, no index
        if not isinstance(d, dict):
            raise ProtocolError("volume: expected an object")
        if d.get("values_per_cell") != 12 or "visibility" in d or Volume._octree_levels(d):
            raise ProtocolError("compression \"shq\" codes the merged volume of R5.1's 12 values per cell (SPEC "
                                "R5.16); the description has %r values per cell%s" % (
                                    d.get("values_per_cell"), ", the probes' visibility" if "visibility" in d else
                                    ", octree levels" if Volume._octree_levels(d) else ""))
        index = d.get("index")
        if index is not None:
            values = index.get("raw_offset") if isinstance(index, dict) else None
            if not _is_int(values) or not 0 <= values <= raw_length:
                raise ProtocolError("volume.index.raw_offset: %r, expected where the values end, in [0, %d]"
                                    % (values, raw_length))
    if values % _SHQ_CELL_BYTES:
        raise ProtocolError("compression \"shq\": %d bytes of values are not whole cells of %d bytes (SPEC R5.16)"
                            % (values, _SHQ_CELL_BYTES))
    return values // _SHQ_CELL_BYTES, raw_length - values


def shq_payload_max(cells, extra):
    """The largest payload C cells and X bytes after them can need (a delta
    that sends every cell): the bound zstd decompresses to."""
    return (_SHQ_HEAD.size + 8 + _SHQ_REGION.size * _SHQ_MAX_REGIONS + _SHQ_SENT_BYTES * cells + (cells + 7) // 8
            + _SHQ_SENT_BYTES_DELTA * cells + extra)


def shq_decode(att, header, base=None):
    """The raw fp32 volume (bytes, ``raw_length`` of them) of a VOLUME or
    GET_VOLUME message of compression "shq" (SPEC R5.16): the header checked
    (format, error_bound, the cells it describes), the attachment
    decompressed (one zstd frame, R5.2) and decoded by ``shq_decode_payload``.
    ``base``: for a delta, the raw bytes this client rebuilt for the tick the
    header's base_tick names (the one it acknowledged)."""
    shq_error_bound(header)
    cells, extra = shq_cells(header)
    keyframe = header.get("keyframe", True)
    if not isinstance(keyframe, bool):
        raise ProtocolError("keyframe: %r, expected true or false" % (keyframe,))
    payload = _zstd_decompress(att, shq_payload_max(cells, extra))
    return shq_decode_payload(payload, header["raw_length"], cells, keyframe, base)


def shq_decode_payload(payload, raw_length, cells, keyframe, base=None):
    """R5.16's payload (the zstd frame's content) -> the raw fp32 volume of
    raw_length bytes whose first ``cells`` cells are the values. A keyframe's
    cells are all sent; a delta's cells not flagged in its bit map keep
    ``base``'s bytes (the raw volume of the acknowledged tick, raw_length
    bytes), and its bytes after the values are XOR'd with the base's. Value
    k of a cell sent is q x 2^x in binary32 (exact; 0 when x = -128), where
    q is the mantissa, or for a delta's cell of mode 1 the mantissa plus the
    base's value in steps of 2^x (rounded half to even), or for a predicted
    keyframe's cell the mantissa plus the previous cell's q scaled to 2^x
    (_shq_predict), modulo 2^16. A delta with flag bit 2 first moves the
    base's cells by its blocks (_shq_move): mode 1 is then the change from
    the moved cell.

    Raises ProtocolError for what the SPEC says a client MUST reject: a
    magic other than "SHQ1", flags other than bits 0, 1 and 2 (1 only with 0, 2 only without), a keyframe flag that
    disagrees with the header's ``keyframe``, C or X other than the header's,
    S over C (or a keyframe's S not C), a bit map whose set bits are not S or
    that sets bits past C, a mode other than 0 or 1 (or 1 with x = -128),
    blocks whose counts, regions or exponents are out of range or that move a
    value past binary32, and a length other than 32 + 25 S + X (a keyframe)
    or 32 + B + ceil(C / 8) + 26 S + X (a delta; B the blocks' bytes)."""
    p = bytes(payload)
    values = cells * _SHQ_CELL_BYTES
    if not 0 <= values <= raw_length:
        raise ProtocolError("shq: %d cells do not fit a %d-byte volume" % (cells, raw_length))
    extra = raw_length - values
    if len(p) < _SHQ_HEAD.size or p[:4] != SHQ_MAGIC:
        raise ProtocolError("shq: not an %r payload (%d bytes starting %r)" % (SHQ_MAGIC.decode(), len(p), p[:4]))
    _, flags, n_cells, sent, n_extra = _SHQ_HEAD.unpack_from(p)
    key = bool(flags & _SHQ_FLAG_KEY)
    if (flags & ~(_SHQ_FLAG_KEY | _SHQ_FLAG_PREDICTED | _SHQ_FLAG_BLOCKS) or (flags & _SHQ_FLAG_PREDICTED and not key)
            or (flags & _SHQ_FLAG_BLOCKS and key)):
        raise ProtocolError("shq: unknown flags 0x%x (bit 0 is keyframe, bit 1 predicted, only with bit 0, bit 2 "
                            "blocks, only without bit 0)" % flags)
    predicted = bool(flags & _SHQ_FLAG_PREDICTED)
    if key != bool(keyframe):
        raise ProtocolError("shq: the payload is a %s, the header says keyframe %r" % (
            "keyframe" if key else "delta", keyframe))
    if n_cells != cells or n_extra != extra:
        raise ProtocolError("shq: payload of %d cells and %d bytes after them, the header's volume has %d cells "
                            "and %d" % (n_cells, n_extra, cells, extra))
    if sent > cells or (key and sent != cells):
        raise ProtocolError("shq: %d of %d cells sent%s" % (sent, cells, " in a keyframe, which sends every cell"
                                                            if key else ""))
    if not key and (base is None or len(base) != raw_length):
        raise ProtocolError("shq: a delta needs the base volume of %d bytes, %s" % (
            raw_length, "none was given" if base is None else "got %d" % len(base)))
    blocks, blocks_len = None, 0
    if flags & _SHQ_FLAG_BLOCKS:
        blocks = _shq_blocks(p, _SHQ_HEAD.size, cells)
        blocks_len = blocks[-1]
    map_len = 0 if key else (cells + 7) // 8
    per = _SHQ_SENT_BYTES if key else _SHQ_SENT_BYTES_DELTA
    need = _SHQ_HEAD.size + blocks_len + map_len + per * sent + extra
    if len(p) != need:
        raise ProtocolError("shq: payload of %d bytes, its counts need %d (32 + %d of blocks + %d of bit map + %d x %d "
                            "cells sent + %d)" % (len(p), need, blocks_len, map_len, per, sent, extra))
    bitmap = None
    if not key:
        bitmap = p[_SHQ_HEAD.size + blocks_len:_SHQ_HEAD.size + blocks_len + map_len]
        flagged = bin(int.from_bytes(bitmap, "little")).count("1")
        if flagged != sent or (cells % 8 and bitmap[-1] >> (cells % 8)):
            raise ProtocolError("shq: the bit map flags %d cells%s, the payload sends %d" % (
                flagged, " (some past the %d cells)" % cells if cells % 8 and bitmap[-1] >> (cells % 8) else "",
                sent))
    at = _SHQ_HEAD.size + blocks_len + map_len
    modes = None
    if not key:
        exps, modes = p[at:at + sent], p[at + sent:at + 2 * sent]
        for j, mode in enumerate(modes):
            if mode > _SHQ_RELATIVE or (mode == _SHQ_RELATIVE and exps[j] == 0x80):
                raise ProtocolError("shq: sent cell %d has mode %d%s" % (
                    j, mode, "" if mode > _SHQ_RELATIVE else " with the zero exponent"))
    if blocks is not None:  # the client's cells moved by the blocks, then the cells sent as against that base
        base = _shq_move(p, blocks, bytes(base[:values]), cells) + bytes(base[values:])
    rebuilt = (_shq_values_numpy if _np is not None else _shq_values_stdlib)(p, at, cells, sent, bitmap, modes, base,
                                                                             predicted)
    after = p[at + per * sent:]
    return rebuilt + (after if key else _xor(after, bytes(base[values:])))


def _shq_blocks(p, at, cells):
    """A delta's blocks (SPEC R5.16 bit 2) at p[at:], checked: (regions as
    (first, nx, ny, nz), edge, T blocks, where their exponents start, B the
    section's bytes)."""
    if len(p) < at + 8:
        raise ProtocolError("shq: the blocks' counts are cut off")
    regions, edge = struct.unpack_from("<II", p, at)
    if not 1 <= regions <= _SHQ_MAX_REGIONS or not 1 <= edge <= _SHQ_BLOCK_EDGE_MAX:
        raise ProtocolError("shq: %d regions of blocks of edge %d (1..%d regions, edge 1..%d)" % (
            regions, edge, _SHQ_MAX_REGIONS, _SHQ_BLOCK_EDGE_MAX))
    if len(p) < at + 8 + _SHQ_REGION.size * regions:
        raise ProtocolError("shq: the blocks' regions are cut off")
    regs, end, count = [], 0, 0
    for r in range(regions):
        first, nx, ny, nz = _SHQ_REGION.unpack_from(p, at + 8 + _SHQ_REGION.size * r)
        if not (nx and ny and nz) or first < end or first + nx * ny * nz > cells:
            raise ProtocolError("shq: the blocks' regions are not boxes of the %d cells in order" % cells)
        end = first + nx * ny * nz
        regs.append((first, nx, ny, nz))
        count += -(-nx // edge) * -(-ny // edge) * -(-nz // edge)
    exps_at = at + 8 + _SHQ_REGION.size * regions
    return regs, edge, count, exps_at, 8 + _SHQ_REGION.size * regions + _SHQ_SENT_BYTES * count


def _shq_move(p, blocks, values, cells):
    """The base's values (bytes, cells x 48) moved by the blocks: each block's
    d x 2^x added to every value of its cells that are not all zero, each sum
    rounded to binary32 once; a sum that is not finite is refused."""
    regs, edge, count, at, _ = blocks
    xs = struct.unpack_from("<%db" % count, p, at)
    for t, x in enumerate(xs):
        if x > _SHQ_BLOCK_EXP_MAX:
            raise ProtocolError("shq: block %d has exponent %d (at most %d, or -128)" % (t, x, _SHQ_BLOCK_EXP_MAX))
    lo = at + count
    hi = lo + 12 * count
    if _np is not None:
        return _shq_move_numpy(p, regs, edge, count, xs, lo, values, cells)
    d = [[(z >> 1) ^ -(z & 1) for z in (p[lo + k * count + t] | (p[hi + k * count + t] << 8) for t in range(count))]
         for k in range(12)]
    out = array.array("f")
    out.frombytes(values)
    if sys.byteorder != "little":
        out.byteswap()
    t0 = 0
    for first, nx, ny, nz in regs:
        bx, by = -(-nx // edge), -(-ny // edge)
        i = first
        for zc in range(nz):
            for yc in range(ny):
                for xc in range(nx):
                    t = t0 + xc // edge + bx * (yc // edge + by * (zc // edge))
                    c = 12 * i
                    i += 1
                    if xs[t] == _SHQ_ZERO_EXP or not any(out[c:c + 12]):
                        continue
                    for k in range(12):
                        v = _f32(out[c + k] + math.ldexp(d[k][t], xs[t]))  # once to binary32: binary32 addition
                        if not math.isfinite(v):
                            raise ProtocolError("shq: a block moves a value past binary32's range")
                        out[c + k] = v
        t0 += bx * by * -(-nz // edge)
    if sys.byteorder != "little":
        out.byteswap()
    return out.tobytes()


def _shq_move_numpy(p, regs, edge, count, xs, lo, values, cells):
    """_shq_move with numpy: the same bytes."""
    planes = _np.frombuffer(p, _np.uint8, 24 * count, lo).astype(_np.int32).reshape(2, 12, count)
    z = planes[0] | (planes[1] << 8)
    x = _np.array(xs, _np.int32)
    step = _np.ldexp(((z >> 1) ^ -(z & 1)).T.astype(_np.float64), x[:, None]).astype(_np.float32)  # exact
    vals = _np.frombuffer(values, "<f4", 12 * cells).reshape(cells, 12).astype(_np.float32)
    t0 = 0
    for first, nx, ny, nz in regs:
        bx, by, bz = -(-nx // edge), -(-ny // edge), -(-nz // edge)
        n = bx * by * bz

        def up(a):
            return a.repeat(edge, 0).repeat(edge, 1).repeat(edge, 2)[:nz, :ny, :nx]
        add = up(step[t0:t0 + n].reshape(bz, by, bx, 12))
        moving = up((x[t0:t0 + n] != _SHQ_ZERO_EXP).reshape(bz, by, bx))
        region = vals[first:first + nx * ny * nz].reshape(nz, ny, nx, 12)
        live = moving & (region != 0).any(axis=-1)
        with _np.errstate(over="ignore", invalid="ignore"):
            moved = region[live] + add[live]  # binary32 addition
        if not _np.isfinite(moved).all():
            raise ProtocolError("shq: a block moves a value past binary32's range")
        region[live] = moved
        t0 += n
    return vals.astype("<f4").tobytes()


def _shq_predict(prev_q, prev_x, x):
    """A predicted keyframe's prediction of a cell's mantissa (SPEC R5.16):
    the previous cell's q at exponent prev_x scaled to the cell's 2^x and
    rounded half to even, or 0 where either exponent is -128 or they are
    more than 15 apart (the first cell's predecessor is a zero cell)."""
    if prev_x == _SHQ_ZERO_EXP or x == _SHQ_ZERO_EXP or abs(prev_x - x) > _SHQ_PREDICT_SHIFT_MAX:
        return 0
    return round(math.ldexp(prev_q, prev_x - x))


def _wrap16(v):
    """v modulo 2^16 as a signed 16-bit value."""
    return (v + 32768) % 65536 - 32768


def _shq_unpredict_numpy(r, x):
    """A predicted keyframe's mantissas (sent x 12, int64) from their
    residuals r and exponents x: along each run of one exponent the
    prediction is the previous q itself, so q is the residuals' running sum
    (modulo 2^16) from the run's first cell, predicted from the run before."""
    q = _np.empty_like(r)
    starts = _np.flatnonzero(_np.r_[True, x[1:] != x[:-1]]) if len(x) else _np.zeros(0, _np.int64)
    prev, prev_x = _np.zeros(12, _np.int64), _SHQ_ZERO_EXP
    for s, e in zip(starts, _np.r_[starts[1:], len(x)].astype(_np.int64)):
        xs = int(x[s])
        if xs == _SHQ_ZERO_EXP:  # every cell of the run predicted 0
            q[s:e] = _wrap16(r[s:e])
        else:
            pred = _np.array([_shq_predict(int(v), prev_x, xs) for v in prev], _np.int64)
            q[s:e] = _wrap16(pred + _np.cumsum(r[s:e], axis=0))
        prev, prev_x = q[e - 1], xs
    return q


def _shq_values_numpy(p, at, cells, sent, bitmap, modes, base, predicted=False):
    """The values' bytes (cells x 48) rebuilt with numpy (see shq_decode_payload)."""
    x = _np.frombuffer(p, _np.int8, sent, at).astype(_np.int32)
    planes_at = at + sent + (0 if modes is None else sent)
    planes = _np.frombuffer(p, _np.uint8, 24 * sent, planes_at).astype(_np.int32).reshape(2, 12, sent)
    z = planes[0] | (planes[1] << 8)
    q = ((z >> 1) ^ -(z & 1)).T.astype(_np.float64)  # (sent, 12) mantissas
    if predicted:
        q = _shq_unpredict_numpy(q.astype(_np.int64), x).astype(_np.float64)
    if modes is not None:  # mode 1: the change from the base's cell in steps of 2^x
        sent_at = _np.unpackbits(_np.frombuffer(bitmap, _np.uint8), bitorder="little")[:cells].astype(bool)
        b = _np.frombuffer(base, "<f4", 12 * cells).reshape(cells, 12)[sent_at].astype(_np.float64)
        rel = _np.frombuffer(modes, _np.uint8) == _SHQ_RELATIVE
        q[rel] += _np.rint(_np.ldexp(b[rel], -x[rel][:, None]))
    v = _np.ldexp(q, x[:, None])  # exact in binary64
    v[x == _SHQ_ZERO_EXP] = 0.0
    with _np.errstate(over="ignore", invalid="ignore"):  # past the largest binary32: infinity, as C's cast
        v = _np.where(_np.abs(v) >= _F32_OVERFLOW, _np.copysign(_np.inf, v), v).astype("<f4")
    if bitmap is None:
        return v.tobytes()
    out = _np.frombuffer(base, "<f4", 12 * cells).reshape(cells, 12).copy()
    out[_np.unpackbits(_np.frombuffer(bitmap, _np.uint8), bitorder="little")[:cells].astype(bool)] = v
    return out.tobytes()


def _shq_values_stdlib(p, at, cells, sent, bitmap, modes, base, predicted=False):
    """The values' bytes (cells x 48) rebuilt with the standard library (see
    shq_decode_payload); the same bytes as _shq_values_numpy."""
    exps = struct.unpack_from("<%db" % sent, p, at)
    lo = at + sent + (0 if modes is None else sent)
    hi = lo + 12 * sent
    zs = [[a | (b << 8) for a, b in zip(p[lo + k * sent:lo + (k + 1) * sent], p[hi + k * sent:hi + (k + 1) * sent])]
          for k in range(12)]
    based = None
    if modes is not None:  # the base's cells that were sent, in order, for mode 1
        b = struct.unpack_from("<%df" % (12 * cells), bytes(base))
        based = [b[12 * i:12 * i + 12] for i in range(cells) if bitmap[i >> 3] >> (i & 7) & 1]
    inf = float("inf")
    flat = []
    prev, prev_x = [0] * 12, _SHQ_ZERO_EXP
    for j, (x, *cell) in enumerate(zip(exps, *zs)):
        if predicted:  # the change from the previous cell's prediction, modulo 2^16
            prev = [_wrap16(((z >> 1) ^ -(z & 1)) + _shq_predict(pq, prev_x, x)) for z, pq in zip(cell, prev)]
            prev_x = x
        if x == _SHQ_ZERO_EXP:
            flat.extend((0.0,) * 12)
            continue
        rel = modes is not None and modes[j] == _SHQ_RELATIVE
        for k, z in enumerate(cell):
            q = prev[k] if predicted else (z >> 1) ^ -(z & 1)
            if rel:  # round() of a float is half to even, as the server's nearbyint
                steps = math.ldexp(based[j][k], -x)
                # a base of +-inf or NaN (which no server's stream gives) stays one, as in binary64
                q = q + round(steps) if math.isfinite(steps) else q + steps
            v = math.ldexp(q, x)  # exact in binary64 (q a float only when it is +-inf or NaN)
            flat.append(math.copysign(inf, v) if abs(v) >= _F32_OVERFLOW else v)  # NaN stays NaN
    out = array.array("f")
    if bitmap is None:
        out.fromlist(flat)
    else:
        out.frombytes(bytes(base[:cells * _SHQ_CELL_BYTES]))
        if sys.byteorder != "little":
            out.byteswap()
        j = 0
        for i in range(cells):
            if bitmap[i >> 3] >> (i & 7) & 1:
                out[12 * i:12 * i + 12] = array.array("f", flat[12 * j:12 * j + 12])
                j += 1
    if sys.byteorder != "little":
        out.byteswap()
    return out.tobytes()


def _shq_clean(v):
    """An exact value as the server codes it (R5.16): NaN 0, clamped to +-1e30 (binary32)."""
    return 0.0 if v != v else min(max(v, -_SHQ_VALUE_LIMIT), _SHQ_VALUE_LIMIT)


def shq_cell_magnitude(c):
    """R5.16's M(c) of one cell's 12 values (r0..r3 g0..g3 b0..b3): max over
    channels of L0 |c0| + L1 |(c1, c2, c3)|, the largest |E_ch(n)| of the
    cosine-lobe lookup over all normals (before R5.7's 1 / cell^2); as
    protocol/volume_shq.c's lpvp_shq_cell_magnitude, in binary64."""
    m = 0.0
    for ch in range(0, 12, 4):
        e = SH_LOBE0 * abs(c[ch]) + SH_LOBE1 * math.sqrt(c[ch + 1] * c[ch + 1] + c[ch + 2] * c[ch + 2]
                                                         + c[ch + 3] * c[ch + 3])
        m = e if e > m else m
    return m


def shq_cell_distance(a, b):
    """R5.16's D(a, b) of two cells: max over channels of L0 |a0 - b0| + L1
    |(a1, a2, a3) - (b1, b2, b3)|, the most any lookup at the cell moves from
    one to the other (lpvp_shq_cell_error)."""
    return shq_cell_magnitude([float(x) - float(y) for x, y in zip(a, b)])


def shq_distances(decoded, exact, cells=None):
    """Per cell, D(decoded, exact) and M(exact) (R5.16), for two raw fp32
    volumes (bytes, R5.1: 12 little-endian binary32 values per cell): what a
    client holds and the exact volume of the same tick (GET_VOLUME "fp32",
    "none"), whose values are cleaned as the server codes them (NaN 0,
    clamped to +-1e30). ``cells``: the cells of the values (default: every
    whole cell of ``exact``; what follows them, an index, is not compared).
    Returns (D, M): float64 numpy arrays, or lists without numpy."""
    n = len(exact) // _SHQ_CELL_BYTES if cells is None else int(cells)
    if len(decoded) < n * _SHQ_CELL_BYTES or len(exact) < n * _SHQ_CELL_BYTES:
        raise ValueError("volumes of %d and %d bytes hold fewer than %d cells" % (len(decoded), len(exact), n))
    if _np is not None:
        a = _np.frombuffer(decoded, "<f4", 12 * n).astype(_np.float64).reshape(n, 3, 4)
        c = _np.clip(_np.nan_to_num(_np.frombuffer(exact, "<f4", 12 * n).astype(_np.float64), nan=0.0),
                     -_SHQ_VALUE_LIMIT, _SHQ_VALUE_LIMIT).reshape(n, 3, 4)

        def magnitude(v):
            return (SH_LOBE0 * _np.abs(v[:, :, 0]) + SH_LOBE1 * _np.sqrt(
                v[:, :, 1] * v[:, :, 1] + v[:, :, 2] * v[:, :, 2] + v[:, :, 3] * v[:, :, 3])).max(axis=1)
        return magnitude(a - c), magnitude(c)
    a = struct.unpack_from("<%df" % (12 * n), decoded)
    c = [_shq_clean(v) for v in struct.unpack_from("<%df" % (12 * n), exact)]
    D, M = [], []
    for i in range(0, 12 * n, 12):
        D.append(shq_cell_distance(a[i:i + 12], c[i:i + 12]))
        M.append(shq_cell_magnitude(c[i:i + 12]))
    return D, M


def shq_bound_excess(decoded, exact, bound, cells=None):
    """How far a client's volume is past R5.16's bound: (excess, cell), the
    largest D(decoded, exact) - bound x M(exact) - (1e-6 M + 1e-30) over the
    cells and the cell where it is (``shq_distances``' arguments). The bound
    holds when excess <= 0; the tolerance is float rounding (the server
    compares in binary64 too), and the 1e-30 covers the cells below R5.16's
    magnitude floor, held as zero."""
    D, M = shq_distances(decoded, exact, cells)
    if _np is not None:
        if not len(D):
            return float("-inf"), None
        ex = D - bound * M - (1e-6 * M + 1e-30)
        i = int(_np.argmax(ex))
        return float(ex[i]), i
    worst, at = float("-inf"), None
    for i, (d, m) in enumerate(zip(D, M)):
        ex = d - bound * m - (1e-6 * m + 1e-30)
        if ex > worst:
            worst, at = ex, i
    return worst, at


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


# R5.15's constants (shaders/lpv_shared.h's LPV_PROBES_*, read by techniques/probes/shaders/probes_lookup.glsl)
_PROBES_FACING_FLOOR = 0.2     # w = phi^2 + 0.2
_PROBES_CRUSH = 0.2            # a weight below it is crushed to w^3 / 0.2^2
_PROBES_MIN_VAR = 1e-4         # sigma^2 at least 1e-4 s_k^2
_PROBES_MIN_WEIGHT = 1e-6      # w' = max(w, 1e-6) t: keeps the division defined
PROBES_UNSEEN = 1e-3           # a level whose probes around p see less of it passes p to the next coarser one


def _oct_encode(w):
    """SPEC R5.15's octahedral encoding of a direction: (w_x, w_y) / l with
    l = |w_x| + |w_y| + |w_z| (0 when l is 0), folded over the corners for
    w_z < 0 (sgn 0 = +1)."""
    l1 = abs(w[0]) + abs(w[1]) + abs(w[2])
    u = (w[0] / l1, w[1] / l1) if l1 > 0.0 else (0.0, 0.0)
    if w[2] < 0.0:
        u = ((1.0 - abs(u[1])) * (1.0 if u[0] >= 0.0 else -1.0), (1.0 - abs(u[0])) * (1.0 if u[1] >= 0.0 else -1.0))
    return u


def _oct_bilinear(side, w):
    """The four texels (row * side + column) around direction w's place on a
    side x side octahedral map and their bilinear weights (SPEC R5.15)."""
    b, b1, f = [0, 0], [0, 0], [0.0, 0.0]
    u = _oct_encode(w)
    for a in range(2):  # a = 0: the column, a = 1: the row
        s = min(max((u[a] * 0.5 + 0.5) * side - 0.5, 0.0), float(side - 1))
        b[a] = min(int(math.floor(s)), max(side - 2, 0))
        f[a] = s - b[a]
        b1[a] = min(b[a] + 1, side - 1)
    return ((b[1] * side + b[0], (1.0 - f[0]) * (1.0 - f[1])), (b[1] * side + b1[0], f[0] * (1.0 - f[1])),
            (b1[1] * side + b[0], (1.0 - f[0]) * f[1]), (b1[1] * side + b1[0], f[0] * f[1]))


def _probes_inside(level, x):
    """SPEC R5.15 step 1: how far x lies inside a level's box, in its cells
    (the least over the six faces; < 1/2: outside its last probes)."""
    dims, o, s = level[0], level[1], level[2]
    d = None
    for a in range(3):
        u = (x[a] - o[a]) / s
        m = min(u, dims[a] - u)
        d = m if d is None else min(d, m)
    return d


def _probes_level(level, k, probe, irradiance_side, distance_side, bias_cells, p, nh):
    """SPEC R5.15 step 2: (E(k) as [r, g, b], h(k)) from level k's 8 probes
    around p + b s_k n (probe(k, x, y, z): the probe's values)."""
    dims, o, s = level[0], level[1], level[2]
    x = [p[a] + bias_cells * s * nh[a] for a in range(3)]
    c0, f = [0, 0, 0], [0.0, 0.0, 0.0]
    for a in range(3):
        q = min(max((x[a] - o[a]) / s - 0.5, 0.0), float(dims[a] - 1))
        c0[a] = min(int(math.floor(q)), max(dims[a] - 2, 0))
        f[a] = q - c0[a]
    irr_at = 4
    dist_at = 4 + 3 * irradiance_side * irradiance_side
    min_var = _PROBES_MIN_VAR * s * s
    irr_texels = _oct_bilinear(irradiance_side, nh)  # every probe's irradiance is read toward n
    total, seen, acc = 0.0, 0.0, [0.0, 0.0, 0.0]
    for j in range(8):
        e = (j & 1, (j >> 1) & 1, j >> 2)
        c = [min(c0[a] + e[a], dims[a] - 1) for a in range(3)]
        v = probe(k, c[0], c[1], c[2])
        if v[3] == 0.0:
            continue  # off: inside geometry
        m = [o[a] + (c[a] + 0.5) * s + v[a] for a in range(3)]
        t = 1.0
        for a in range(3):
            t *= f[a] if e[a] else 1.0 - f[a]
        r = [m[a] - p[a] for a in range(3)]
        rl = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
        phi = (sum(r[a] / rl * nh[a] for a in range(3)) + 1.0) * 0.5 if rl > 0.0 else 1.0
        w = phi * phi + _PROBES_FACING_FLOOR
        d = [x[a] - m[a] for a in range(3)]
        dl = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
        toward = [d[a] / dl for a in range(3)] if dl > 0.0 else nh
        mu = mu2 = 0.0
        for texel, tw in _oct_bilinear(distance_side, toward):
            mu += tw * v[dist_at + 2 * texel]
            mu2 += tw * v[dist_at + 2 * texel + 1]
        if dl > mu:  # the one-sided Chebyshev bound, cubed
            var = max(mu2 - mu * mu, min_var)
            cheb = var / (var + (dl - mu) * (dl - mu))
            w *= cheb * cheb * cheb
        if w < _PROBES_CRUSH:
            w = w * w * w / (_PROBES_CRUSH * _PROBES_CRUSH)
        seen += w * t
        w = max(w, _PROBES_MIN_WEIGHT) * t
        for texel, tw in irr_texels:
            for ch in range(3):
                acc[ch] += w * tw * v[irr_at + 3 * texel + ch]
        total += w
    if not total > 0.0:
        return [0.0, 0.0, 0.0], seen
    return [a / total for a in acc], seen


def probes_irradiance(levels, probe, irradiance_side, distance_side, bias_cells, p, n):
    """SPEC R5.15's lookup: E (W/m^2, r, g, b) at surface point p with normal
    n from technique probes' visibility: ``levels`` the volume's levels,
    finest first, each (dims, origin, cell_size); ``probe(k, x, y, z)`` the
    V values of level k's probe at cell (x, y, z) (offset x y z, active, the
    irradiance map, the distance map); ``irradiance_side``,
    ``distance_side`` and ``bias_cells`` the description's. As
    techniques/probes/shaders/probes_lookup.glsl (lpv_irradiance; its CPU
    oracle techniques/probes/core/probes_lookup.c) computes it, in double
    precision (R5.15: binary32 or better) from p and n rounded to binary32
    (what QUERY_IRRADIANCE carries): the level k0 whose probes
    surround p, each level's 8 probes weighed trilinear x the back-face term
    x the Chebyshev bound of their distance moments (small weights crushed),
    a coarser level where the probes around p do not see it (h < 1e-3), and
    the blend into the next coarser level over the last two cells."""
    p = [_f32(float(v)) for v in p]
    n = [_f32(float(v)) for v in n]
    if not all(math.isfinite(v) for v in p + n):
        return (0.0, 0.0, 0.0)
    ln = math.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2])
    if not 1e-8 < ln < 1e18:  # R5.15: no direction, or one binary32 cannot normalise
        return (0.0, 0.0, 0.0)
    nh = [v / ln for v in n]
    K = len(levels)

    def at(k):
        return _probes_level(levels[k], k, probe, irradiance_side, distance_side, bias_cells, p, nh)
    # 1. the level first asked: the first whose last probes surround p
    k = next((i for i in range(K - 1) if _probes_inside(levels[i], p) >= 0.5), K - 1)
    # 2. + 3. its light, or a coarser level's where its probes around p do not see p
    e, h = at(k)
    while h < PROBES_UNSEEN and k + 1 < K:
        k += 1
        e, h = at(k)
    # 4. blended into the next coarser level over the last two cells
    w = min(max((_probes_inside(levels[k], p) - 0.5) * 0.5, 0.0), 1.0)
    if w < 1.0 and k + 1 < K:
        c, hc = at(k + 1)
        if hc >= PROBES_UNSEEN:
            e = [c[i] + (e[i] - c[i]) * w for i in range(3)]
    return tuple(e)


class Visibility(object):
    """The probes' visibility of a GET_VOLUME content "visibility" reply
    (SPEC R5.15): ``probes`` (P, a probe per cell of every level, in the
    levels' cell order), ``irradiance_side`` (I), ``distance_side`` (D),
    ``values_per_probe`` (V = 4 + 3 I^2 + 2 D^2), ``bias_cells`` and
    ``first`` (each level's first probe). ``data``: the P x V binary32
    values, a float32 numpy array of shape (P, V) when numpy is available
    (``offsets`` (P, 3), ``active`` (P,), ``irradiance`` (P, I*I, 3) and
    ``distance`` (P, D*D, 2) are views of it), else a flat ``array('f')``.
    ``probe(i)`` is probe i's V values as a list in any case."""

    def __init__(self, desc, values, levels):
        self.probes = int(desc["probes"])
        self.irradiance_side = int(desc["irradiance_side"])
        self.distance_side = int(desc["distance_side"])
        self.values_per_probe = int(desc["values_per_probe"])
        self.bias_cells = float(desc["bias_cells"])
        self.description = desc
        self.first, at = [], 0
        for lv in levels:
            self.first.append(at)
            at += lv.cells
        P, V, I, D = self.probes, self.values_per_probe, self.irradiance_side, self.distance_side
        if len(values) != P * V or at != P:
            raise ProtocolError("visibility of %d values for %d probes x %d values (the levels have %d cells)" % (
                len(values), P, V, at))
        self.offsets = self.active = self.irradiance = self.distance = None
        if _np is not None:
            values = values.reshape(P, V)
            self.offsets = values[:, 0:3]
            self.active = values[:, 3]
            self.irradiance = values[:, 4:4 + 3 * I * I].reshape(P, I * I, 3)
            self.distance = values[:, 4 + 3 * I * I:].reshape(P, D * D, 2)
        self.data = values

    def probe(self, i):
        """Probe i's V values (offset x y z, active, I^2 x r g b, D^2 x mean
        mean-square) as a list of floats."""
        if _np is not None:
            return self.data[i].tolist()
        V = self.values_per_probe
        return list(self.data[i * V:(i + 1) * V])


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

    Technique probes' GET_VOLUME content "visibility" (SPEC R5.15;
    ``content`` "visibility"): the merged volume plus ``visibility``, a
    ``Visibility`` (the probes' offsets, switches and octahedral maps);
    ``irradiance()`` and ``probes_irradiance()`` are then R5.15's lookup
    (``probes_irradiance``). Every other volume has ``visibility`` None.

    ``compression`` is the header's; a volume of compression "shq" (SPEC
    R5.16) holds quantised values, each cell within ``error_bound`` x its
    magnitude of the exact volume's (``shq_distances``, ``shq_bound_excess``).

    ``content`` is what the request asked for: None for a VOLUME stream
    message or a GET_VOLUME without content (or "merged" / "levels", read
    from the description), "visibility" for GET_VOLUME content
    "visibility". A description with a ``visibility`` key is refused unless
    ``content`` is "visibility", and a "visibility" reply without one is
    refused too (SPEC R5.15).
    """

    def __init__(self, header, raw, content=None):
        self.header = header
        self.raw = raw  # the raw (decompressed, delta-resolved) bytes
        self.tick = header.get("tick")
        self.revision = header.get("revision")
        self.format = header.get("format")
        # "none", "zstd" or "shq"; for "shq" (SPEC R5.16) the bound the
        # values hold: every cell within error_bound x its magnitude of the
        # exact volume's (None for the other compressions)
        self.compression = header.get("compression", "none")
        self.error_bound = shq_error_bound(header) if self.compression == SHQ_COMPRESSION else None
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
        vis = desc.get("visibility")
        if vis is not None and content != VISIBILITY_CONTENT:
            raise ProtocolError("volume.visibility in a reply to %s: the probes' visibility comes only with "
                                "GET_VOLUME content %r (SPEC R5.15)" % (
                                    "GET_VOLUME content %r" % content if content is not None else
                                    "a VOLUME stream message or GET_VOLUME without content (merged)",
                                    VISIBILITY_CONTENT))
        if content == VISIBILITY_CONTENT and vis is None:
            raise ProtocolError("GET_VOLUME content %r answered without volume.visibility (technique %r; SPEC R5.15)"
                                % (VISIBILITY_CONTENT, desc.get("technique")))
        if vis is not None and not self.keyframe:
            raise ProtocolError("a content %r volume that is not a keyframe (SPEC R5.15: always a keyframe)"
                                % VISIBILITY_CONTENT)
        # SPEC R5.13: GET_VOLUME content "levels" describes an octree's levels
        # (the cascades then are level 0 alone); else the levels are the cascades
        octree = self._octree_levels(desc)
        self.iv = self._iv_levels(desc)
        self.iv_neighbours = desc.get("iv_neighbours") if self.iv else None
        self.units = desc.get("units") or header.get("units") or LPV_UNITS
        self.content = "levels" if octree else VISIBILITY_CONTENT if vis is not None else "merged"
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
        values_end = int(index["raw_offset"]) if index is not None else \
            int(vis["raw_offset"]) if vis is not None else len(raw)
        if vis is not None and len(raw) != values_end + int(vis["raw_length"]):
            raise ProtocolError("volume of %d bytes, the description has %d bytes of values and %d of visibility" % (
                len(raw), values_end, int(vis["raw_length"])))
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
        # SPEC R5.15: the probes' visibility, binary32 whatever the format, after the levels' values
        self.visibility = None
        if vis is not None:
            self.visibility = Visibility(vis, _floats(raw[values_end:], "fp32"), self.levels)

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
        if "visibility" in d and (Volume._octree_levels(d) or Volume._iv_levels(d)):
            raise ProtocolError("volume.visibility with %r levels: the probes' visibility goes with the merged "
                                "cascades' volume only (SPEC R5.15)" % (levels[0].get("role"),))
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
        if "visibility" in d:
            Volume._check_visibility(d, specs, header)
        return d

    @staticmethod
    def _check_visibility(d, specs, header):
        """R5.15: the probes' visibility (GET_VOLUME content "visibility"): P =
        the levels' cells together, I in 1..16, D in 1..32, V = 4 + 3 I^2 +
        2 D^2, value_type "f32", bias_cells >= 0, raw_offset = the levels'
        values' bytes, raw_length = P x V x 4 and the header's raw_length
        their sum; over the merged levels (role "cascade", far field off, the
        12 SH values in one volume, no index)."""
        vis = d["visibility"]
        if not isinstance(vis, dict):
            raise ProtocolError("volume.visibility: expected an object, got %r (SPEC R5.15)" % (vis,))

        def integer(key, lo, hi):
            v = vis.get(key)
            if not _is_int(v) or not lo <= v <= hi:
                raise ProtocolError("volume.visibility.%s: %r, expected an integer in [%d, %d] (SPEC R5.15)"
                                    % (key, v, lo, hi))
            return v
        levels = d["levels"]
        if d.get("far_field") is not False or any(lv.get("role") != "cascade" for lv in levels) \
                or d.get("index") is not None or d.get("volumes_per_level") != 1 \
                or tuple(d.get("values") or ()) != LOOKUP_VALUES or d.get("units") != LPV_UNITS:
            raise ProtocolError("volume.visibility over levels of roles %r, far_field %r, index %r, %r volume(s) of "
                                "%r in %r: the probes' visibility goes with their merged volume (role \"cascade\", "
                                "far_field false, no index, the 12 SH values in one volume, %s; SPEC R5.15)" % (
                                    [lv.get("role") for lv in levels], d.get("far_field"), d.get("index"),
                                    d.get("volumes_per_level"), d.get("values"), d.get("units"), LPV_UNITS))
        cells = sum(int(c.get("cells") or 0) for c in specs)
        P = vis.get("probes")
        if not _is_int(P) or P != cells:
            raise ProtocolError("volume.visibility.probes: %r, the levels have %d cells (a probe a cell; SPEC R5.15)"
                                % (P, cells))
        I = integer("irradiance_side", 1, MAX_IRRADIANCE_SIDE)
        D = integer("distance_side", 1, MAX_DISTANCE_SIDE)
        V = 4 + 3 * I * I + 2 * D * D
        if not _is_int(vis.get("values_per_probe")) or vis["values_per_probe"] != V:
            raise ProtocolError("volume.visibility.values_per_probe: %r, sides %d and %d give 4 + 3 x %d^2 + 2 x "
                                "%d^2 = %d (SPEC R5.15)" % (vis.get("values_per_probe"), I, D, I, D, V))
        if vis.get("value_type") != VISIBILITY_VALUE_TYPE:
            raise ProtocolError("volume.visibility.value_type: %r, expected %r whatever the format (SPEC R5.15)"
                                % (vis.get("value_type"), VISIBILITY_VALUE_TYPE))
        b = vis.get("bias_cells")
        if not isinstance(b, (int, float)) or isinstance(b, bool) or not (math.isfinite(b) and b >= 0.0):
            raise ProtocolError("volume.visibility.bias_cells: %r, expected a finite number >= 0 (SPEC R5.15)"
                                % (b,))
        fmt = header.get("format")
        if fmt not in ("fp16", "fp32"):
            raise ProtocolError("unknown volume format %r" % (fmt,))
        values_bytes = cells * 12 * (2 if fmt == "fp16" else 4)
        if not _is_int(vis.get("raw_offset")) or vis["raw_offset"] != values_bytes:
            raise ProtocolError("volume.visibility.raw_offset: %r, the levels' values (%d cells x 12 %s) end at "
                                "byte %d (SPEC R5.15)" % (vis.get("raw_offset"), cells, fmt, values_bytes))
        if not _is_int(vis.get("raw_length")) or vis["raw_length"] != P * V * 4:
            raise ProtocolError("volume.visibility.raw_length: %r, expected %d probes x %d values x 4 = %d "
                                "(SPEC R5.15)" % (vis.get("raw_length"), P, V, P * V * 4))
        if "raw_length" in header and header["raw_length"] != values_bytes + P * V * 4:
            raise ProtocolError("raw_length: %r, the levels' values (%d bytes) and the visibility (%d) make %d "
                                "(SPEC R5.15)" % (header["raw_length"], values_bytes, P * V * 4,
                                                  values_bytes + P * V * 4))
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
        iv_neighbours); technique probes' content "visibility"
        (``visibility``): R5.15's (``probes_irradiance``). Raises LayoutError
        (naming the layout) for a volume none of the lookups reads."""
        self._check_lookup()
        if self.visibility is not None:
            return self.probes_irradiance(p, n)
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

    def probes_irradiance(self, p, n):
        """E(n) in W/m^2 (r, g, b) at surface point p with normal n by SPEC
        R5.15's lookup, the one the server's QUERY_IRRADIANCE uses for
        technique probes: the probes' visibility weighs each of the 8 probes
        around p (``probes_irradiance``). Raises LayoutError naming the
        technique and content for a volume without the visibility (ask
        ``Client.get_volume(content="visibility")`` of a probes session)."""
        vis = self.visibility
        if vis is None:
            raise LayoutError("R5.15's lookup reads the probes' visibility, which this volume (technique %r, content "
                              "%r) does not carry: it comes only with GET_VOLUME content %r from a session of "
                              "technique %r (SPEC R5.15)" % (self.technique, self.content, VISIBILITY_CONTENT,
                                                             PROBES_TECHNIQUE))
        levels = [(lv.dims, lv.origin, lv.cell_size) for lv in self.levels]
        first, dims = vis.first, [lv.dims for lv in self.levels]
        cache = {}

        def probe(k, x, y, z):
            i = first[k] + x + dims[k][0] * (y + dims[k][1] * z)
            v = cache.get(i)
            if v is None:
                v = cache[i] = vis.probe(i)
            return v
        return probes_irradiance(levels, probe, vis.irradiance_side, vis.distance_side, vis.bias_cells, p, n)
