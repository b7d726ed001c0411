"""lpvd_session.py - the session of the lpvd Python client: ``Client``, one
connection to the daemon (framing, requests and replies, the stream of
volumes and frames with their delta bases), and ``Frame``.

Standard library only (json, socket, struct); numpy is used when it is
importable (query answers then come back as float32 arrays). One of the
modules of the client; import ``lpvd_client``, which re-exports every name.

The protocol is protocol/SPEC.md; section numbers below refer to it.
"""

import json
import socket
import struct
import time

from lpvd_protocol import (ERROR_NAMES, HEADER, MAGIC, MSG, REPLY_BIT, SERVER_BYE, VERSION, LpvdError,
                           ProtocolError, _decompress, _default_compression, _parse_address, default_address)
from lpvd_volume import SHQ_COMPRESSION, Volume, _np, _xor, shq_decode


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

    @property
    def volume_codecs(self):
        """The volume compressions the server sends and shq's error bounds
        (HELLO "volume_codecs", SPEC R5.16): {"compression": ["none", "zstd",
        "shq"], "error_bound": {"min", "max", "default"}}; None from a server
        without shq."""
        codecs = (self.hello_reply or {}).get("volume_codecs")
        return dict(codecs) if isinstance(codecs, dict) else None

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

    def subscribe(self, stream="volume", format=None, compression=None, delta=None, error_bound=None):
        """SUBSCRIBE. A volume stream defaults to fp32 with deltas; with
        compression "shq" (SPEC R5.16) each volume is quantised to
        ``error_bound`` (None: the server's default, HELLO's
        volume_codecs), a delta re-sends only the cells that moved beyond it,
        and a tick whose cells all stayed within it sends no VOLUME at all
        (the volume held stays within the bound of the newest tick)."""
        body = {"stream": stream}
        if stream == "volume":
            body["format"] = format or "fp32"
            body["compression"] = compression or _default_compression()
            body["delta"] = True if delta is None else bool(delta)
            if error_bound is not None:
                body["error_bound"] = error_bound
        else:
            if format is not None:
                body["format"] = format
            body["compression"] = compression or _default_compression()
            if delta is not None:
                body["delta"] = bool(delta)
        return self.request(MSG["SUBSCRIBE"], body)[0]

    def unsubscribe(self, stream="volume"):
        return self.request(MSG["UNSUBSCRIBE"], {"stream": stream})[0]

    def get_volume(self, format="fp32", compression=None, content=None, error_bound=None):
        """GET_VOLUME, decoded to a ``Volume`` (a keyframe). compression "shq"
        (SPEC R5.16, merged content only): the fp32 volume quantised so that
        each cell is within ``error_bound`` (None: the server's default) x
        its magnitude of the exact one's. content: "merged"
        (None: the server's default, the merged volume), "levels" (SPEC
        R5.13: an octree technique's levels, ``Volume.levels``, and its index
        volume, ``Volume.index``) or "visibility" (SPEC R5.15: technique
        probes' merged volume and the probes' visibility,
        ``Volume.visibility``, which ``Volume.irradiance`` then weighs the
        probes with as the server does; binary32 whatever the format).
        Technique iv's volume (SPEC R5.14) comes as ``Volume.iv``, its
        occupancy as ``Volume.index``."""
        body = {"format": format, "compression": compression or _default_compression()}
        if content is not None:
            body["content"] = content
        if error_bound is not None:
            body["error_bound"] = error_bound
        hdr, att = self.request(MSG["GET_VOLUME"], body)
        return self._decode_volume(hdr, att, ack=False, content=content)

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
        if tick in self._acked:  # sent again (a new subscription): the copy acknowledged last is the base
            self._acked[tick] = raw
            return
        self._acked[tick] = raw
        self._acked_order.append(tick)
        while len(self._acked_order) > self.keep_acked:
            self._acked.pop(self._acked_order.pop(0), None)

    def _decode_volume(self, hdr, att, ack, content=None):
        base = None
        if not hdr.get("keyframe", True):
            tick = hdr.get("base_tick")
            if tick not in self._acked:
                raise ProtocolError("delta against tick %r which this client does not hold" % (tick,))
            base = self._acked[tick]
        if hdr.get("compression") == SHQ_COMPRESSION:  # SPEC R5.16: the cells sent replace the base's
            raw = shq_decode(att, hdr, base)
        else:
            raw = _decompress(att, hdr.get("compression", "none"), hdr.get("raw_length", len(att)))
            if "raw_length" in hdr and len(raw) != hdr["raw_length"]:
                raise ProtocolError("volume of %d bytes, header says raw_length %d" % (len(raw), hdr["raw_length"]))
            if base is not None:
                raw = _xor(raw, base)
        vol = Volume(hdr, raw, content)
        if ack and vol.tick is not None:
            self._remember(vol.tick, raw)
            self.ack(vol.tick)
        return vol

    def _decode_frame(self, hdr, att):
        data = att
        if hdr.get("format") == "rgba8":
            data = _decompress(att, hdr.get("compression", "none"), hdr.get("raw_length", len(att)))
        return Frame(hdr, bytes(data))

    def tick_volume(self, timeout=60.0):
        """TICK, then the volume stream's answer to it: (the TICK reply, the
        VOLUME of that tick as a ``Volume``, decoded and acknowledged, or None
        when the server sent none). A subscriber to compression "shq" with
        deltas gets no VOLUME for a tick that moved no cell beyond its bound
        (SPEC R5.16): the volume it holds stays within the bound of that
        tick, and STATS "session_stream_unchanged" counts the tick, which is
        how this tells "none" from "not yet" (a VOLUME sent before a STATS
        reply arrives before it). Frames that arrive meanwhile stay queued
        for ``next_message``. ProtocolError when neither comes within
        ``timeout`` seconds."""
        before = self.stats().get("session_stream_unchanged", 0)
        t = self.tick()
        deadline = time.monotonic() + timeout
        while True:
            at = next((i for i, m in enumerate(self._stream_queue) if m[0] == MSG["VOLUME"]), None)
            if at is not None:
                _, body, att = self._stream_queue.pop(at)
                vol = self._decode_volume(body, att, ack=True)
                if vol.tick is None or vol.tick >= t.get("tick", 0):
                    return t, vol
                continue  # an earlier tick's, late: this tick's answer is still to come
            if self.stats().get("session_stream_unchanged", 0) > before:
                return t, None
            if time.monotonic() > deadline:
                raise ProtocolError("no VOLUME for tick %s and no unchanged tick counted within %g s"
                                    % (t.get("tick"), timeout))
            time.sleep(0.01)

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
