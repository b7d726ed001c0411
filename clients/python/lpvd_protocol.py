"""lpvd_protocol.py - the wire protocol of the lpvd Python client, version 1:
the frame header, message types, ERROR codes and their exceptions, addresses,
attachments' compression and the tick plan's passes.

Standard library only (os, struct); the ``zstandard`` module is used when
importable, otherwise the client asks the server for ``"compression":
"none"`` (the standard library has no zstd). Attachments that are zstd
whatever the client asks (a volume of compression "shq", SPEC R5.16) are
decompressed, without ``zstandard``, by the system's libzstd through ctypes
(the library lpvd itself links). One of the modules of the client; import
``lpvd_client``, which re-exports every name.

The protocol is protocol/SPEC.md; section numbers below refer to it.
"""

import ctypes
import ctypes.util
import os
import struct

try:  # optional
    import zstandard as _zstd
except ImportError:  # pragma: no cover - depends on the machine
    _zstd = None

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


_libzstd = []  # [the loaded library or None] once looked for


def _load_libzstd():
    """The system's libzstd (ctypes.CDLL) or None, looked for once, on the first
    zstd attachment that arrives without the ``zstandard`` module: a client
    that never sees one never runs ldconfig to find it."""
    if not _libzstd:
        lib = None
        for name in (ctypes.util.find_library("zstd"), "libzstd.so.1", "libzstd.1.dylib"):
            if not name:
                continue
            try:
                lib = ctypes.CDLL(name)
            except OSError:
                continue
            lib.ZSTD_decompress.restype = ctypes.c_size_t
            lib.ZSTD_decompress.argtypes = (ctypes.c_void_p, ctypes.c_size_t, ctypes.c_char_p, ctypes.c_size_t)
            lib.ZSTD_isError.restype = ctypes.c_uint
            lib.ZSTD_isError.argtypes = (ctypes.c_size_t,)
            lib.ZSTD_getErrorName.restype = ctypes.c_char_p
            lib.ZSTD_getErrorName.argtypes = (ctypes.c_size_t,)
            break
        _libzstd.append(lib)
    return _libzstd[0]


def zstd_decoder():
    """What decompresses zstd attachments here: "zstandard" (the module),
    "libzstd" (the system library through ctypes) or None (neither: a zstd
    attachment, e.g. every "shq" volume, raises ProtocolError)."""
    if _zstd is not None:
        return "zstandard"
    return "libzstd" if _load_libzstd() is not None else None


def _zstd_decompress(data, max_output):
    """One zstd frame (SPEC R5.2) decompressed to at most max_output bytes;
    ProtocolError when it is not one or holds more."""
    if _zstd is not None:
        try:
            # decompress() trusts a frame's declared size over max_output_size
            size = _zstd.frame_content_size(data)
            if size > max_output:
                raise ProtocolError("zstd attachment of %d bytes whose frame holds %d, more than the %d expected"
                                    % (len(data), size, max_output))
            return _zstd.ZstdDecompressor().decompress(data, max_output_size=max(max_output, 1))
        except _zstd.ZstdError as e:
            raise ProtocolError("zstd attachment of %d bytes: %s" % (len(data), e))
    lib = _load_libzstd()
    if lib is None:
        raise ProtocolError("zstd-compressed attachment, but neither the 'zstandard' module nor the system's "
                            "libzstd is there to decompress it")
    data = bytes(data)
    out = ctypes.create_string_buffer(max(max_output, 1))
    n = lib.ZSTD_decompress(out, len(out), data, len(data))
    if lib.ZSTD_isError(n):
        raise ProtocolError("zstd attachment of %d bytes (at most %d decompressed): %s" % (
            len(data), max_output, lib.ZSTD_getErrorName(n).decode("ascii", "replace")))
    return out.raw[:n]


def _decompress(data, compression, raw_length):
    if compression in (None, "none"):
        return bytes(data)
    if compression == "zstd":
        return _zstd_decompress(data, raw_length)
    raise ProtocolError("unknown compression %r" % compression)


def _default_compression():
    return "zstd" if _zstd is not None else "none"
