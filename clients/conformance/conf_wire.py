"""conf_wire.py - the lpvd wire protocol v1 as a small client: message types and error codes
(SPEC sections 2-4), frames (encode_frame, Frame) and a blocking connection (Conn) that checks
every server frame (R1.3, R2.1). Part of the conformance suite (lpvd_conformance.py), and the
client library that tests/reliability/ and bench/serve_bench.py use through lpvd_conformance."""

import json
import socket
import struct
import time


# ---------------------------------------------------------------------------
# Protocol constants (SPEC sections 2-4)

MAGIC = b"LPVD"
VERSION = 1
HEADER = struct.Struct("<4sHHIIII")  # magic, version, type, request_id, flags, json_length, attachment_length
HEADER_SIZE = 24

HELLO = 0x0001
SCENE_LOAD = 0x0002
SCENE_UPDATE = 0x0003
LIGHT_SET = 0x0004
LIGHT_REMOVE = 0x0005
CAMERA_SET = 0x0006
CONFIG = 0x0007
TICK = 0x0008
SUBSCRIBE = 0x0009
UNSUBSCRIBE = 0x000A
GET_VOLUME = 0x000B
GET_FRAME = 0x000C
QUERY_IRRADIANCE = 0x000D
STATS = 0x000E
BYE = 0x000F
ACK = 0x0010
VOLUME = 0x0101
FRAME = 0x0102
REPLY = 0x8000
ERROR = 0xFFFF
BYE_REPLY = BYE | REPLY

TYPE_NAMES = {
    HELLO: "HELLO", SCENE_LOAD: "SCENE_LOAD", SCENE_UPDATE: "SCENE_UPDATE", LIGHT_SET: "LIGHT_SET",
    LIGHT_REMOVE: "LIGHT_REMOVE", CAMERA_SET: "CAMERA_SET", CONFIG: "CONFIG", TICK: "TICK",
    SUBSCRIBE: "SUBSCRIBE", UNSUBSCRIBE: "UNSUBSCRIBE", GET_VOLUME: "GET_VOLUME", GET_FRAME: "GET_FRAME",
    QUERY_IRRADIANCE: "QUERY_IRRADIANCE", STATS: "STATS", BYE: "BYE", ACK: "ACK", VOLUME: "VOLUME",
    FRAME: "FRAME", ERROR: "ERROR",
}

ERROR_CODES = {
    "BAD_MAGIC": 1, "BAD_VERSION": 2, "BAD_FRAME": 3, "TOO_LARGE": 4, "BAD_JSON": 5, "UNKNOWN_TYPE": 6,
    "BAD_FIELD": 7, "UNAUTHORIZED": 8, "HELLO_REQUIRED": 9, "NOT_READY": 10, "SCENE_INVALID": 11,
    "PATH_REFUSED": 12, "LIMIT": 13, "INTERNAL": 14, "SHUTTING_DOWN": 15,
}
ERROR_NAMES = {v: k for k, v in ERROR_CODES.items()}

DEFAULT_MAX_BODY = 1 << 20
DEFAULT_MAX_MESSAGE = 256 << 20
ZSTD_MAGIC = b"\x28\xb5\x2f\xfd"  # 0xFD2FB528 little-endian


def type_name(t):
    if t in TYPE_NAMES:
        return TYPE_NAMES[t]
    if t & REPLY and (t & ~REPLY) in TYPE_NAMES:
        return TYPE_NAMES[t & ~REPLY] + "_REPLY"
    return "0x%04X" % t


# ---------------------------------------------------------------------------
# Frames


def encode_frame(ftype, request_id, body=None, attachment=b"", *, magic=MAGIC, version=VERSION, flags=0,
                 raw_body=None, json_length=None, attachment_length=None):
    """Builds one frame. body: a JSON-able value (default {}), or raw_body: the exact body bytes.
    json_length / attachment_length override the header fields (to build lying frames)."""
    if raw_body is None:
        raw_body = json.dumps({} if body is None else body, separators=(",", ":")).encode("utf-8")
    jl = len(raw_body) if json_length is None else json_length
    al = len(attachment) if attachment_length is None else attachment_length
    return HEADER.pack(magic, version, ftype, request_id & 0xFFFFFFFF, flags, jl, al) + raw_body + attachment


class Frame:
    __slots__ = ("type", "rid", "body", "raw_body", "att", "t_recv")

    def __init__(self, ftype, rid, body, raw_body, att):
        self.type, self.rid, self.body, self.raw_body, self.att = ftype, rid, body, raw_body, att
        self.t_recv = time.monotonic()

    @property
    def is_error(self):
        return self.type == ERROR

    @property
    def err_name(self):
        if self.type == ERROR and isinstance(self.body, dict):
            return self.body.get("name")
        return None

    def __repr__(self):
        b = json.dumps(self.body)
        if len(b) > 240:
            b = b[:240] + "..."
        return "%s rid=%d body=%s att=%d" % (type_name(self.type), self.rid, b, len(self.att))


class Closed(Exception):
    """The peer closed (EOF or reset)."""


class Violation(Exception):
    """A server frame that breaks R1.3/R2.1 (bad magic/version/flags/JSON)."""


class Conn:
    """A blocking connection with a receive buffer. endpoint: ('unix', path) or ('tcp', host, port)."""

    def __init__(self, endpoint, timeout=10.0, rcvbuf=None, connect_timeout=5.0):
        self.endpoint = endpoint
        self.timeout = timeout
        if endpoint[0] == "unix":
            self.sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        else:
            self.sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
            self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        if rcvbuf:
            self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, rcvbuf)
        self.sock.settimeout(connect_timeout)
        try:
            self.sock.connect(endpoint[1] if endpoint[0] == "unix" else (endpoint[1], endpoint[2]))
        except BaseException:
            self.sock.close()
            raise
        self.buf = bytearray()
        self.next_rid = 1
        self.streams = []  # stream messages (request_id 0) set aside by recv_reply
        self.eof = False
        self.bytes_received = 0

    # -- sending
    def send_raw(self, data):
        self.sock.settimeout(self.timeout)
        self.sock.sendall(data)

    def rid(self):
        r = self.next_rid
        self.next_rid += 1
        return r

    def send(self, ftype, body=None, att=b"", rid=None):
        if rid is None:
            rid = self.rid()
        self.send_raw(encode_frame(ftype, rid, body, att))
        return rid

    # -- receiving
    def _fill(self, n, deadline):
        while len(self.buf) < n:
            if self.eof:
                raise Closed("connection closed by the server")
            left = deadline - time.monotonic()
            if left <= 0:
                raise socket.timeout("no data within the time limit")
            self.sock.settimeout(left)
            try:
                chunk = self.sock.recv(max(65536, n - len(self.buf)))
            except (ConnectionResetError, BrokenPipeError) as e:
                self.eof = True
                raise Closed("connection reset by the server (%s)" % e)
            if not chunk:
                self.eof = True
                raise Closed("connection closed by the server")
            self.bytes_received += len(chunk)
            self.buf += chunk

    def recv(self, timeout=None):
        """The next frame (any type). Raises Closed, socket.timeout or Violation."""
        deadline = time.monotonic() + (self.timeout if timeout is None else timeout)
        self._fill(HEADER_SIZE, deadline)
        magic, ver, ftype, rid, flags, jl, al = HEADER.unpack_from(self.buf, 0)
        if magic != MAGIC:
            raise Violation("server frame with magic %r (R2.1)" % bytes(magic))
        if ver != VERSION:
            raise Violation("server frame with version %d (R2.1)" % ver)
        if flags != 0:
            raise Violation("server frame with flags 0x%x (R2.4)" % flags)
        if jl < 2:
            raise Violation("server frame with json_length %d < 2 (R2.1)" % jl)
        self._fill(HEADER_SIZE + jl + al, deadline)
        raw = bytes(self.buf[HEADER_SIZE:HEADER_SIZE + jl])
        att = bytes(self.buf[HEADER_SIZE + jl:HEADER_SIZE + jl + al])
        del self.buf[:HEADER_SIZE + jl + al]
        try:
            body = json.loads(raw.decode("utf-8"))
        except (UnicodeDecodeError, ValueError) as e:
            raise Violation("server frame %s with a body that is not UTF-8 JSON: %s" % (type_name(ftype), e))
        if not isinstance(body, dict):
            raise Violation("server frame %s whose body is not a JSON object" % type_name(ftype))
        return Frame(ftype, rid, body, raw, att)

    def recv_reply(self, rid=None, timeout=None):
        """The next frame that is not an unsolicited stream message (VOLUME/FRAME with request_id 0);
        those are appended to self.streams. The caller checks the request_id."""
        deadline = time.monotonic() + (self.timeout if timeout is None else timeout)
        while True:
            f = self.recv(max(0.0, deadline - time.monotonic()))
            if f.rid == 0 and f.type in (VOLUME, FRAME) and rid != 0:
                self.streams.append(f)
                continue
            return f

    def recv_stream(self, ftype=VOLUME, timeout=None):
        """The next stream message of ftype (from the set-aside list first); other frames are kept aside
        in self.others."""
        for i, f in enumerate(self.streams):
            if f.type == ftype:
                return self.streams.pop(i)
        deadline = time.monotonic() + (self.timeout if timeout is None else timeout)
        while True:
            f = self.recv(max(0.0, deadline - time.monotonic()))
            if f.rid == 0 and f.type == ftype:
                return f
            self.streams.append(f)

    def request(self, ftype, body=None, att=b"", timeout=None):
        rid = self.send(ftype, body, att)
        return self.recv_reply(rid, timeout)

    def expect_closed(self, timeout=3.0):
        """True if the server closes (EOF/reset) within timeout, discarding anything else received."""
        deadline = time.monotonic() + timeout
        try:
            while True:
                left = deadline - time.monotonic()
                if left <= 0:
                    return False
                self.sock.settimeout(left)
                chunk = self.sock.recv(65536)
                if not chunk:
                    return True
        except (ConnectionResetError, BrokenPipeError):
            return True
        except socket.timeout:
            return False

    def close(self):
        try:
            self.sock.close()
        except OSError:
            pass

    def __enter__(self):
        return self

    def __exit__(self, *a):
        self.close()


def parse_endpoint(spec):
    """'unix:PATH', 'PATH' (contains '/'), or 'HOST:PORT'."""
    if spec.startswith("unix:"):
        return ("unix", spec[5:])
    if "/" in spec:
        return ("unix", spec)
    host, _, port = spec.rpartition(":")
    return ("tcp", host or "127.0.0.1", int(port))


def endpoint_str(ep):
    return ep[1] if ep[0] == "unix" else "%s:%d" % (ep[1], ep[2])
