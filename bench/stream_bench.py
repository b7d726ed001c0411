#!/usr/bin/env python3
"""stream_bench.py - what a thin client pays for lpvd's streamed volume (issue 35): bytes, error and lag.

    python3 bench/stream_bench.py                     # starts its own daemon (build/server/lpvd or --lpvd)
    python3 bench/stream_bench.py --quick             # fewer updates
    python3 bench/stream_bench.py --only 1,2          # some sections

A benchmark, not a test: nothing is asserted. Prints Markdown tables
(docs/streaming.md records them):
  1. bytes per update and the client's error, per codec: the volume stream of
     3 cascades of 32^3 (technique lpv) while LIGHT_SET moves a point light
     1 cm before each TICK; today's fp16 / fp32 + zstd XOR deltas beside
     compression "shq" (SPEC R5.16) at several bounds. After every VOLUME the
     client's volume is compared with a GET_VOLUME fp32 of the same tick: per
     cell D / M (the largest change of the cell's lookup over all normals, as
     a fraction of the cell's magnitude), and at 256 random points of the
     surfaces the camera sees, with their normals, the error of the client's
     lookup as a fraction of the exact volume's lookup there;
  2. a static scene: TICKs with nothing changed, bytes received per update;
  3. 1, 10 and 50 subscribers of one world (their lights moved in lock-step
     so that they stay one world), bytes per update per subscriber, the
     stream's Mbit/s at 10 and 30 updates per second, and the server's
     encoding time (STATS "encode", on its work threads) against the tick's;
  4. lag: after a light moves 0.3 m, the TICKs until the client's shq volume
     is within the bound of the converged answer at the points of section 1,
     per technique.
--set KEY=VALUE adds a CONFIG setting to the lpv runs (e.g. --set
smooth_injection=true). --save DIR instead writes each technique's exact volumes of 16 updates
(the input of build/bench/lpvd-shq-codec, bench/shq_codec.c).
numpy is required (the error figures).
"""

import argparse
import json
import os
import random
import socket
import sys
import threading
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "clients", "conformance"))
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
sys.path.insert(0, os.path.join(ROOT, "tests", "reliability"))

import lpvd_conformance as lc  # noqa: E402
import harness  # noqa: E402
import lpvd_volume as lv  # noqa: E402
from lpvd_protocol import _zstd_decompress  # noqa: E402

CONFIG = {"technique": "lpv", "grid": [32, 32, 32], "cascades": 3}
LIGHT = {"id": "mv", "type": "point", "intensity": 10.0, "position": [0.0, 1.2, 0.0]}
CAMERA = {"eye": [0.0, 1.0, 3.9], "target": [0.0, 1.0, 0.0], "fov_deg": 45.0, "width": 64, "height": 64}


def pct(vals, p):
    return float(np.percentile(np.asarray(vals, dtype=np.float64), p)) if len(vals) else float("nan")


def frame_bytes(m):
    return 24 + len(m.raw_body) + len(m.att)


class Client:
    """A session that keeps the volume it rebuilt from the stream."""

    def __init__(self, bench, sub=None, config=None, light=None):
        self.c = bench.session(config, light)
        self.sub = sub
        self.raw = {}  # tick -> raw bytes rebuilt
        if sub is not None:
            bench.req(self.c, lc.SUBSCRIBE, dict(sub, stream="volume"))

    def receive(self, timeout):
        """The next VOLUME decoded and ACKed, or None when none came within timeout."""
        try:
            m = self.c.recv_stream(lc.VOLUME, timeout=timeout)
        except socket.timeout:
            return None
        h = m.body
        base = None if h["keyframe"] else self.raw[h["base_tick"]]
        if h["compression"] == "shq":
            raw = lv.shq_decode(m.att, h, base)
        else:
            raw = bytes(_zstd_decompress(m.att, h["raw_length"])) if h["compression"] == "zstd" else bytes(m.att)
            if base is not None:
                raw = (np.frombuffer(raw, np.uint8) ^ np.frombuffer(base, np.uint8)).tobytes()
        self.raw[h["tick"]] = raw  # a base until a newer one is ACKed and the server has had it (a few ticks)
        for t in sorted(self.raw)[:-4]:
            del self.raw[t]
        self.c.send(lc.ACK, {"stream": "volume", "tick": h["tick"]})
        return m, raw

    def close(self):
        self.c.close()


class Bench:
    def __init__(self, ep, quick):
        self.ep = ep
        self.quick = quick
        self.glb = lc.box_scene_glb(with_light=False)
        self.points = None
        self.bounds = None

    def conn(self):
        c = lc.Conn(self.ep, timeout=600.0)
        self.req(c, lc.HELLO, {"version": 1, "client": "stream_bench"})
        return c

    def req(self, c, t, body=None, att=b"", timeout=None):
        r = c.request(t, body or {}, att, timeout)
        if r.type != t | lc.REPLY:
            raise RuntimeError("%s: %r" % (lc.type_name(t), r))
        return r

    def session(self, config=None, light=None, camera=True):
        """A session on self.glb (its bounds in self.bounds) with config, the
        bench's camera (camera False: the scene's default) and light."""
        c = self.conn()
        self.bounds = self.req(c, lc.SCENE_LOAD, {}, self.glb).body["scene"]["bounds"]
        self.req(c, lc.CONFIG, config or CONFIG)
        if camera:
            self.req(c, lc.CAMERA_SET, CAMERA)
        self.req(c, lc.LIGHT_SET, light or LIGHT)
        return c

    def stats(self, c):
        return self.req(c, lc.STATS).body

    def exact(self, c):
        r = self.req(c, lc.GET_VOLUME, {"format": "fp32", "compression": "none"})
        return r.body, bytes(r.att)

    def view_points(self, n=256):
        """Surface points the camera sees, with their normals: random (fixed
        seed) on the box's floor, ceiling, back and side walls (the open
        front faces the camera), 2 cm from the edges."""
        if self.points is None:
            rnd = random.Random(35)
            faces = [(1, 0.0, (0, 1, 0)), (1, 2.0, (0, -1, 0)), (2, -1.0, (0, 0, 1)), (0, -1.0, (1, 0, 0)),
                     (0, 1.0, (-1, 0, 0))]  # (axis, coordinate, inward normal)
            self.points = []
            for i in range(n):
                axis, at, normal = faces[i % len(faces)]
                p = [rnd.uniform(-0.98, 0.98), rnd.uniform(0.02, 1.98), rnd.uniform(-0.98, 0.98)]
                p[axis] = at
                self.points.append((p, normal))
        return self.points

    def lookups(self, header, raw):
        """E (W/m^2, rgb) at the view's points by the client's lookup (SPEC R5.7, R5.14)."""
        vol = lv.Volume(header, raw)
        return np.array([vol.irradiance(p, nn) for p, nn in self.view_points()])

    @staticmethod
    def point_errors(e_client, e_exact):
        """Per lit point, the largest channel's |dE| / the point's largest channel of E: the error of the
        client's lookup as a fraction of the lookup from the exact volume."""
        scale = np.abs(e_exact).max(axis=1)
        err = np.abs(e_client - e_exact).max(axis=1)
        keep = scale > 0
        return err[keep] / scale[keep]

    # 1 ------------------------------------------------------------------
    def codecs(self):
        n = 6 if self.quick else 16
        subs = [("fp16 + zstd, XOR delta (today)", {"format": "fp16", "compression": "zstd", "delta": True}),
                ("fp32 + zstd, XOR delta", {"format": "fp32", "compression": "zstd", "delta": True})]
        for e in (0.002, 0.005, 0.01, 0.02, 0.05):
            subs.append(("shq, bound %g" % e, {"compression": "shq", "error_bound": e, "delta": True}))
        rows = []
        for label, sub in subs:
            light = dict(LIGHT)
            cl = Client(self, sub, light=light)
            keys, deltas, frames, dm_p99, dm_max, pt_p99, pt_max, missing = [], [], [], [], [], [], [], 0
            enc0 = self.stats(cl.c).get("encode", {})
            tick_ms = []
            for i in range(n):
                light["position"] = [0.01 * i, 1.2, 0.0]
                self.req(cl.c, lc.LIGHT_SET, light)
                tick_ms.append(self.req(cl.c, lc.TICK, timeout=600).body["stats"].get("tick_ms", float("nan")))
                got = cl.receive(timeout=10.0)
                hx, ex = self.exact(cl.c)
                if got is None:
                    missing += 1
                    frames.append(0)
                    continue
                m, raw = got
                if m.body["tick"] != hx["tick"]:
                    raise RuntimeError("VOLUME of tick %s, GET_VOLUME of %s" % (m.body["tick"], hx["tick"]))
                (keys if m.body["keyframe"] else deltas).append(len(m.att))
                if i:
                    frames.append(frame_bytes(m))
                raw32 = raw if m.body["format"] == "fp32" else np.frombuffer(raw, "<f2").astype("<f4").tobytes()
                D, M = lv.shq_distances(raw32, ex, lv.shq_cells(hx)[0])
                r = D[M > 0] / M[M > 0]
                dm_p99.append(pct(r, 99))
                dm_max.append(float(r.max()))
                pe = self.point_errors(self.lookups(m.body, raw), self.lookups(hx, ex))
                pt_p99.append(pct(pe, 99))
                pt_max.append(float(pe.max()))
            enc1 = self.stats(cl.c).get("encode", {})
            cl.close()
            enc_ms = (enc1.get("volume_cpu_ms", 0) - enc0.get("volume_cpu_ms", 0)) / max(1, enc1.get("volumes", 0) -
                                                                                  enc0.get("volumes", 0))
            rows.append((label, keys, deltas, frames, missing, max(dm_p99), max(dm_max), max(pt_p99), max(pt_max),
                         enc_ms, float(np.median(tick_ms[1:]))))
        base = np.mean(rows[0][2]) if rows[0][2] else float("nan")
        print("### 1. Bytes and error per update: 3 cascades of 32^3 (technique lpv), light moved 1 cm per update, "
              "%d updates\n" % n)
        print("Bytes: the attachment (keyframe: the first update; deltas: the rest) and the whole VOLUME frame "
              "(header JSON with the plan included; an update with no VOLUME counts 0). Error: the client's volume "
              "against GET_VOLUME fp32 of the same tick, the worst update's figure. Encode: the server's work-thread "
              "time per VOLUME (STATS \"encode\"), the tick's median beside it.\n")
        print("| codec | keyframe bytes | delta bytes (mean) | delta / today's | frame bytes per update (mean) | "
              "updates without a VOLUME | cell D/M p99 | cell D/M max | point error p99 | point error max | "
              "encode ms | tick ms |")
        print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
        for label, keys, deltas, frames, missing, dp, dmx, pp, pmx, enc, tms in rows:
            md = np.mean(deltas) if deltas else float("nan")
            print("| %s | %s | %.0f | %.3f | %.0f | %d of %d | %.2e | %.2e | %.2e | %.2e | %.1f | %.0f |" % (
                label, keys[0] if keys else "-", md, md / base, np.mean(frames) if frames else 0, missing,
                len(frames) + 1, dp, dmx, pp, pmx, enc, tms))
        print()

    # 2 ------------------------------------------------------------------
    def static(self):
        n = 5 if self.quick else 10
        print("### 2. A static scene: TICKs with nothing changed (3 x 32^3, lpv)\n")
        print("| codec | updates | VOLUMEs received | VOLUME bytes per update | STATS session_stream_unchanged |")
        print("|---|---:|---:|---:|---:|")
        for label, sub in (("fp16 + zstd, XOR delta", {"format": "fp16", "compression": "zstd", "delta": True}),
                           ("shq, bound 0.01", {"compression": "shq", "error_bound": 0.01, "delta": True})):
            cl = Client(self, sub)
            self.req(cl.c, lc.TICK, timeout=600)
            cl.receive(timeout=10.0)  # the keyframe
            got, bytes_ = 0, 0
            for _ in range(n):
                self.req(cl.c, lc.TICK, timeout=600)
                m = cl.receive(timeout=1.0)
                if m is not None:
                    got += 1
                    bytes_ += frame_bytes(m[0])
            s = self.stats(cl.c)
            cl.close()
            print("| %s | %d | %d | %.0f | %s |" % (label, n, got, bytes_ / n, s.get("session_stream_unchanged")))
        print()

    # 3 ------------------------------------------------------------------
    def subscribers(self):
        k = 3 if self.quick else 6
        counts = (1, 10) if self.quick else (1, 10, 50)
        rows = []
        for label, sub in (("fp16 + zstd, XOR delta", {"format": "fp16", "compression": "zstd", "delta": True}),
                           ("shq, bound 0.01", {"compression": "shq", "error_bound": 0.01, "delta": True})):
            for nsub in counts:
                lights = [dict(LIGHT) for _ in range(nsub)]
                cls = [Client(self, sub, light=li) for li in lights]
                for cl in cls:  # the first ticks: keyframes, then whatever the others' TICKs made
                    self.req(cl.c, lc.TICK, timeout=600)
                for cl in cls:
                    while cl.receive(timeout=2.0) is not None:
                        pass
                s0 = self.stats(cls[0].c)
                got, bytes_, ticks, errors, keys = [0], [0], [], [], [0]
                lock = threading.Lock()
                barrier = threading.Barrier(nsub)

                def run(cl, light):
                    try:
                        for r in range(k):
                            light["position"] = [0.01 * (r + 1), 1.2, 0.0]
                            barrier.wait(600)
                            self.req(cl.c, lc.LIGHT_SET, light)
                            barrier.wait(600)
                            t = self.req(cl.c, lc.TICK, timeout=600).body["stats"].get("tick_ms")
                            m = cl.receive(timeout=30.0)
                            with lock:
                                ticks.append(t)
                                if m is not None:
                                    got[0] += 1
                                    keys[0] += 1 if m[0].body["keyframe"] else 0
                                    bytes_[0] += frame_bytes(m[0])
                    except Exception as e:
                        with lock:
                            errors.append(str(e))
                        barrier.abort()

                threads = [threading.Thread(target=run, args=(cl, li)) for cl, li in zip(cls, lights)]
                t0 = time.monotonic()
                for t in threads:
                    t.start()
                for t in threads:
                    t.join(3600)
                wall = time.monotonic() - t0
                s1 = self.stats(cls[0].c)
                for cl in cls:
                    cl.close()
                enc = s1["encode"]["volume_cpu_ms"] - s0["encode"]["volume_cpu_ms"]
                nenc = s1["encode"]["volumes"] - s0["encode"]["volumes"]
                computed = s1["ticks"] - s0["ticks"]
                per = bytes_[0] / (k * nsub)
                rows.append((label, nsub, k, "%d (%d keyframes)" % (got[0], keys[0]), per, enc / max(1, computed), nenc,
                             computed,
                             float(np.median([t for t in ticks if t])), wall, errors))
        print("### 3. Subscribers of one world (3 x 32^3, lpv, light moved 1 cm per update in lock-step)\n")
        print("Bytes per update: per subscriber, the whole VOLUME frame. Mbit/s: that x subscribers x the rate. "
              "Encoding: the server's work-thread time for all subscribers' VOLUMEs of one update (2 threads "
              "share it), beside the median tick the TICK replies report.\n")
        print("| codec | subscribers | updates | VOLUMEs | bytes per update per subscriber | Mbit/s at 10 Hz | "
              "Mbit/s at 30 Hz | encode ms per update (all subscribers) | ticks computed | tick ms | wall s |")
        print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
        for label, nsub, k_, got, per, enc, nenc, computed, tms, wall, errors in rows:
            print("| %s | %d | %d | %s | %.0f | %.2f | %.2f | %.1f | %d | %.0f | %.1f |%s" % (
                label, nsub, k_, got, per, per * nsub * 10 * 8 / 1e6, per * nsub * 30 * 8 / 1e6, enc, computed, tms,
                wall, " errors: %s" % errors[:2] if errors else ""))
        print()

    # 4 ------------------------------------------------------------------
    def lag(self):
        n = 12 if self.quick else 40
        bound = 0.01
        print("### 4. Lag: TICKs from a 0.3 m light move to the first VOLUME within the bound (shq %g, delta)\n"
              % bound)
        print("Converged: GET_VOLUME fp32 after %d TICKs without a change. Within: the client's lookups at the "
              "256 surface points of section 1 within %g of the converged lookup at the 99th percentile.\n"
              % (n, bound))
        print("| technique | grid | TICKs to within the bound | ms of ticks | VOLUMEs received | p99 error after "
              "1 TICK | p99 error at the end |")
        print("|---|---|---:|---:|---:|---:|---:|")
        for tech, cfg in TECHNIQUES:
            light = dict(LIGHT)
            cl = Client(self, {"compression": "shq", "error_bound": bound, "delta": True}, config=cfg, light=light)
            for _ in range(n):  # settled before the move
                self.req(cl.c, lc.TICK, timeout=600)
                cl.receive(timeout=2.0)
            light["position"] = [0.3, 1.2, 0.0]
            self.req(cl.c, lc.LIGHT_SET, light)
            held, hdr, series, tms, vols = None, None, [], [], 0
            raws = []
            for i in range(n):
                tms.append(self.req(cl.c, lc.TICK, timeout=600).body["stats"].get("tick_ms", 0.0))
                got = cl.receive(timeout=2.0)
                if got is not None:
                    vols += 1
                    hdr, held = got[0].body, got[1]
                raws.append((hdr, held))
            hx, ex = self.exact(cl.c)
            conv = self.lookups(hx, ex)
            for hdr_i, raw_i in raws:
                series.append(pct(self.point_errors(self.lookups(hdr_i, raw_i), conv), 99) if raw_i else float("inf"))
            cl.close()
            first = next((i + 1 for i, e in enumerate(series) if e <= bound), None)
            print("| %s | %s | %s | %s | %d | %.3g | %.3g |" % (
                tech, "x".join(str(x) for x in hx["grid"]["dims"]), first if first else "> %d" % n,
                "%.0f" % sum(tms[:first]) if first else "-", vols, series[0], series[-1]))
        print()


TECHNIQUES = (("lpv", CONFIG), ("octree", {"technique": "octree", "grid": [32, 32, 32]}), ("iv", {"technique": "iv"}),
              ("probes", {"technique": "probes", "grid": [16, 16, 16]}))


def save(bench, out, n=16, scene=None):
    """The exact volumes (fp32, the values without any index) of n updates of
    each technique while the light moves 1 cm per update, as OUT/TECH-NN.bin:
    the input of lpvd-shq-codec (bench/shq_codec.c), and OUT/TECH.regions,
    its --region flags (the cascades' dims). With scene (a .glb
    path): that scene instead of the box, the light 10 % of the scene's
    height above its centre, moved 0.5 % of its width per update (1 cm is to
    the 2 m box)."""
    os.makedirs(out, exist_ok=True)
    if scene:
        with open(scene, "rb") as f:
            bench.glb = f.read()
    for name, cfg in TECHNIQUES:
        light = dict(LIGHT)
        c = bench.session(cfg, light, camera=not scene)
        start, step = [0.0, 1.2, 0.0], 0.01
        if scene:
            b = bench.bounds
            start = [(b[0] + b[3]) / 2, b[4] + 0.1 * (b[4] - b[1]), (b[2] + b[5]) / 2]
            step = 0.005 * (b[3] - b[0])
        for i in range(n):
            light["position"] = [start[0] + step * i, start[1], start[2]]
            bench.req(c, lc.LIGHT_SET, light)
            bench.req(c, lc.TICK, timeout=600)
            hx, ex = bench.exact(c)
            with open(os.path.join(out, "%s-%02d.bin" % (name, i)), "wb") as f:
                f.write(ex[:lv.shq_cells(hx)[0] * 48])
        with open(os.path.join(out, "%s.regions" % name), "w") as f:  # lpvd-shq-codec's --region per cascade
            f.write(" ".join("--region %dx%dx%d" % tuple(k["dims"]) for k in hx["cascades"]) + "\n")
        c.close()
        print("saved %d volumes of %s in %s" % (n, name, out))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--lpvd", help="lpvd binary (default build/server/lpvd)")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--only", help="comma list of sections 1-4")
    ap.add_argument("--save", metavar="DIR", help="only save each technique's exact volumes for lpvd-shq-codec")
    ap.add_argument("--scene", metavar="GLB", help="with --save: this scene instead of the box")
    ap.add_argument("--set", metavar="KEY=VALUE", action="append", default=[],
                    help="a CONFIG setting of the lpv runs (JSON value, or a string), e.g. smooth_injection=true")
    args = ap.parse_args()
    for kv in args.set:
        key, _, value = kv.partition("=")
        try:
            CONFIG[key] = json.loads(value)
        except ValueError:
            CONFIG[key] = value
    daemon = harness.Daemon(harness.find_lpvd(args.lpvd), optional=[("--max-clients", "128"),
                                                                    ("--max-preauth", "128")])
    daemon.start()
    b = Bench(("unix", daemon.unix), args.quick)
    sections = {"1": b.codecs, "2": b.static, "3": b.subscribers, "4": b.lag}
    try:
        if args.save:
            save(b, args.save, scene=args.scene)
            return 0
        print("## lpvd stream benchmark (%s), %d CPU cores, %s\n" % (
            time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), os.cpu_count(), daemon.binary))
        for k in (args.only or "1,2,3,4").split(","):
            sections[k.strip()]()
            sys.stdout.flush()
    finally:
        daemon.stop()
    return 0


if __name__ == "__main__":
    sys.exit(main())
