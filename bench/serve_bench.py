#!/usr/bin/env python3
"""serve_bench.py - figures for `lpvd serve` (a benchmark, not a test: nothing is asserted).

    python3 bench/serve_bench.py                      # starts its own daemon (build-t/server/lpvd or --lpvd)
    python3 bench/serve_bench.py --unix /tmp/x.sock   # against a running daemon
    python3 bench/serve_bench.py --quick              # shorter runs

Prints Markdown tables:
  1. irradiance queries per second over one connection, 64k-point batches
     (sequential, and 4 batches pipelined); target >= 2 M points/s;
  2. tick-to-client latency of the volume stream: TICK sent -> VOLUME
     received (fp16+zstd), the light moved 1 cm before each TICK so that the
     tick computes (the planner serves an unchanged scene's cached volume),
     and with periodic ticks (tick_rate_hz) the VOLUME inter-arrival times;
  3. bytes per streamed volume, keyframe vs XOR delta, while LIGHT_SET moves a
     point light 1 cm per tick (fp16+zstd and fp32+zstd, 32^3 grid);
  4. 64 concurrent clients: HELLO + TICK + GET_VOLUME each, total time and
     per-request latency p50/p99;
  5. sharing: 8 clients with the same scene and config (one shared world,
     R7.2) vs 1 client vs 8 clients with distinct lights, the lights moved
     1 cm in lock-step before each TICK so that every round computes: tick
     throughput and the server's STATS "worlds".
Pure Python standard library (zstd payloads are measured, not decoded).
"""

import argparse
import array
import os
import random
import socket
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "clients", "conformance"))
sys.path.insert(0, os.path.join(ROOT, "tests", "reliability"))

import lpvd_conformance as lc  # noqa: E402
import harness  # noqa: E402

GRID = [32, 32, 32]


def pct(vals, p):
    if not vals:
        return float("nan")
    s = sorted(vals)
    return s[min(len(s) - 1, max(0, int(round(p / 100.0 * (len(s) - 1)))))]


def ms(x):
    return "%.1f" % (x * 1000.0)


class Bench:
    def __init__(self, ep, token, quick):
        self.ep = ep
        self.token = token
        self.quick = quick
        self.glb = lc.box_scene_glb()
        self.out = []

    def conn(self, timeout=120.0):
        c = lc.Conn(self.ep, timeout=timeout)
        body = {"version": 1, "client": "serve_bench"}
        if self.token:
            body["token"] = self.token
        r = c.request(lc.HELLO, body)
        if r.type != lc.HELLO | lc.REPLY:
            raise RuntimeError("HELLO: %r" % r)
        return c

    def req(self, c, t, body=None, att=b"", timeout=None):
        r = c.request(t, body or {}, att, timeout)
        if r.type != t | lc.REPLY:
            raise RuntimeError("%s: %r" % (lc.type_name(t), r))
        return r

    def scene(self, config=None, light=None, load=True):
        c = self.conn()
        if load:
            self.req(c, lc.SCENE_LOAD, {}, self.glb)
        self.req(c, lc.CONFIG, config or {"grid": GRID, "iterations": 8, "rsm_size": 256})
        if light:
            self.req(c, lc.LIGHT_SET, light)
        return c

    def emit(self, text=""):
        print(text, flush=True)
        self.out.append(text)

    # 1 ------------------------------------------------------------------
    def irradiance(self):
        n = 65536
        c = self.scene(light={"id": "q", "type": "point", "intensity": 10.0, "position": [0, 1.5, 0]})
        self.req(c, lc.TICK, timeout=120)
        rnd = random.Random(5)
        a = array.array("f")
        for _ in range(n):
            a.extend((rnd.uniform(-1, 1), rnd.uniform(0, 2), rnd.uniform(-1, 1), 0.0, 1.0, 0.0))
        if sys.byteorder != "little":
            a.byteswap()
        pts = a.tobytes()
        self.req(c, lc.QUERY_IRRADIANCE, {"count": n}, pts)  # warm-up
        batches = 4 if self.quick else 12
        t0 = time.monotonic()
        lat = []
        for _ in range(batches):
            t1 = time.monotonic()
            r = self.req(c, lc.QUERY_IRRADIANCE, {"count": n}, pts)
            lat.append(time.monotonic() - t1)
            assert len(r.att) == n * 12
        seq = n * batches / (time.monotonic() - t0)
        depth = 4
        t0 = time.monotonic()
        for _ in range(batches // depth or 1):
            rids = [c.send(lc.QUERY_IRRADIANCE, {"count": n}, pts) for _ in range(depth)]
            for rid in rids:
                r = c.recv_reply(rid)
                if r.type != lc.QUERY_IRRADIANCE | lc.REPLY:
                    raise RuntimeError("query: %r" % r)
        pip = n * depth * (batches // depth or 1) / (time.monotonic() - t0)
        c.close()
        self.emit("### 1. Irradiance queries (one connection, 65 536 points per batch, %d^3 grid)" % GRID[0])
        self.emit()
        self.emit("| mode | points/s | batch latency p50 (ms) | p99 (ms) | target |")
        self.emit("|---|---:|---:|---:|---|")
        self.emit("| sequential | %.2f M | %s | %s | >= 2 M points/s: %s |" % (seq / 1e6, ms(pct(lat, 50)),
                                                                         ms(pct(lat, 99)),
                                                                         "met" if seq >= 2e6 else "not met"))
        self.emit("| 4 in flight | %.2f M | | | >= 2 M points/s: %s |" % (pip / 1e6,
                                                                         "met" if pip >= 2e6 else "not met"))
        self.emit()

    # 2 ------------------------------------------------------------------
    def latency(self):
        light = {"id": "lat", "type": "point", "intensity": 10.0, "position": [0.0, 1.5, 0.0]}
        c = self.scene(light=light)
        self.req(c, lc.SUBSCRIBE, {"stream": "volume", "format": "fp16", "compression": "zstd"})
        n = 8 if self.quick else 25
        lat, tick_lat = [], []
        for i in range(n + 1):
            # the light moves 1 cm before each tick: with nothing changed the
            # planner would serve the cached volume instead of computing one
            light["position"] = [0.01 * (i % 2), 1.5, 0.0]
            self.req(c, lc.LIGHT_SET, light)
            t0 = time.monotonic()
            rid = c.send(lc.TICK, {})
            r = c.recv_reply(rid)
            t1 = time.monotonic()
            v = c.recv_stream(lc.VOLUME)
            t2 = time.monotonic()
            if i:
                lat.append(t2 - t0)
                tick_lat.append(t1 - t0)
        rows = [("TICK request -> TICK reply", tick_lat), ("TICK request -> VOLUME received", lat)]
        # periodic ticks
        per_rows = []
        rate = 5.0
        r = c.request(lc.CONFIG, {"tick_rate_hz": rate})
        if r.type == lc.CONFIG | lc.REPLY:
            dur = 4.0 if self.quick else 10.0
            arrivals = []
            t_end = time.monotonic() + dur
            while time.monotonic() < t_end:
                try:
                    v = c.recv_stream(lc.VOLUME, timeout=max(0.1, t_end - time.monotonic()))
                    arrivals.append(v.t_recv)
                except socket.timeout:
                    break
            c.request(lc.CONFIG, {"tick_rate_hz": 0})
            iv = [b - a for a, b in zip(arrivals, arrivals[1:])]
            per_rows.append(("periodic %g Hz: VOLUME inter-arrival" % rate, iv, len(arrivals) / dur))
        else:
            per_rows.append(("periodic ticks refused: %s" % r.body.get("message", r), [], 0.0))
        c.close()
        self.emit("### 2. Tick-to-client latency (volume stream, fp16+zstd, %d^3, 8 iterations, the light moved 1 cm "
                  "before each tick, so each tick computes)" % GRID[0])
        self.emit()
        self.emit("| measure | n | p50 (ms) | p99 (ms) | max (ms) |")
        self.emit("|---|---:|---:|---:|---:|")
        for name, v in rows:
            self.emit("| %s | %d | %s | %s | %s |" % (name, len(v), ms(pct(v, 50)), ms(pct(v, 99)), ms(max(v))))
        for name, v, hz in per_rows:
            if v:
                self.emit("| %s (%.2f volumes/s received) | %d | %s | %s | %s |" % (name, hz, len(v), ms(pct(v, 50)),
                                                                                 ms(pct(v, 99)), ms(max(v))))
            else:
                self.emit("| %s | 0 | | | |" % name)
        self.emit()

    # 3 ------------------------------------------------------------------
    def delta_sizes(self):
        rows = []
        n = 6 if self.quick else 15
        for fmt in ("fp16", "fp32"):
            light = {"id": "mv", "type": "point", "intensity": 10.0, "position": [0.0, 1.5, 0.0]}
            c = self.scene(light=light)
            self.req(c, lc.SUBSCRIBE, {"stream": "volume", "format": fmt, "compression": "zstd", "delta": True})
            keys, deltas, raw = [], [], None
            for i in range(n):
                light["position"] = [0.01 * i, 1.5, 0.0]
                self.req(c, lc.LIGHT_SET, light)
                self.req(c, lc.TICK)
                v = c.recv_stream(lc.VOLUME)
                raw = v.body.get("raw_length")
                (keys if v.body.get("keyframe") else deltas).append(len(v.att))
                c.send(lc.ACK, {"stream": "volume", "tick": v.body.get("tick")})
            c.close()
            rows.append((fmt, raw, keys, deltas))
        self.emit("### 3. Bytes per streamed volume: keyframe vs XOR delta (%d^3, light moves 1 cm per tick, zstd)"
                  % GRID[0])
        self.emit()
        self.emit("| format | raw bytes | keyframes (n, mean bytes) | deltas (n, mean bytes) | delta / keyframe |")
        self.emit("|---|---:|---:|---:|---:|")
        for fmt, raw, keys, deltas in rows:
            mk = sum(keys) / len(keys) if keys else float("nan")
            md = sum(deltas) / len(deltas) if deltas else float("nan")
            self.emit("| %s+zstd | %s | %d, %.0f | %d, %.0f | %s |" % (
                fmt, raw, len(keys), mk, len(deltas), md,
                ("%.2f" % (md / mk)) if keys and deltas else "no deltas received"))
        self.emit()

    # 4 ------------------------------------------------------------------
    def concurrent(self, nclients=64):
        lat = {"HELLO": [], "TICK": [], "GET_VOLUME": []}
        errors = []
        barrier = threading.Barrier(nclients)
        lock = threading.Lock()

        def worker(i):
            try:
                c = lc.Conn(self.ep, timeout=300)
                barrier.wait(60)
                body = {"version": 1, "client": "bench-%d" % i}
                if self.token:
                    body["token"] = self.token
                for name, t, b in (("HELLO", lc.HELLO, body), ("TICK", lc.TICK, {}),
                                   ("GET_VOLUME", lc.GET_VOLUME, {"format": "fp16", "compression": "zstd"})):
                    t0 = time.monotonic()
                    r = c.request(t, b)
                    dt = time.monotonic() - t0
                    if r.type != t | lc.REPLY:
                        raise RuntimeError("%s: %r" % (name, r))
                    with lock:
                        lat[name].append(dt)
                c.close()
            except Exception as e:
                with lock:
                    errors.append("%d: %s" % (i, e))

        threads = [threading.Thread(target=worker, args=(i,)) for i in range(nclients)]
        t0 = time.monotonic()
        for t in threads:
            t.start()
        for t in threads:
            t.join(600)
        total = time.monotonic() - t0
        allv = lat["HELLO"] + lat["TICK"] + lat["GET_VOLUME"]
        self.emit("### 4. %d concurrent clients (HELLO + TICK + GET_VOLUME each, default scene and config)" % nclients)
        self.emit()
        self.emit("| request | n | p50 (ms) | p99 (ms) | max (ms) |")
        self.emit("|---|---:|---:|---:|---:|")
        for name in ("HELLO", "TICK", "GET_VOLUME"):
            v = lat[name]
            if v:
                self.emit("| %s | %d | %s | %s | %s |" % (name, len(v), ms(pct(v, 50)), ms(pct(v, 99)), ms(max(v))))
        if allv:
            self.emit("| all | %d | %s | %s | %s |" % (len(allv), ms(pct(allv, 50)), ms(pct(allv, 99)), ms(max(allv))))
        self.emit()
        self.emit("Total wall time %.2f s for %d clients; %d errors%s" % (total, nclients, len(errors),
                                                                     (": " + "; ".join(errors[:3])) if errors else ""))
        self.emit()

    # 5 ------------------------------------------------------------------
    def stats(self):
        c = self.conn()
        r = c.request(lc.STATS, {})
        c.close()
        return r.body if r.type == lc.STATS | lc.REPLY else {}

    def sharing(self):
        k = 3 if self.quick else 6
        rows = []
        for label, nclients, distinct in (("1 client", 1, False), ("8 clients, same scene + config", 8, False),
                                          ("8 clients, distinct lights", 8, True)):
            conns, lights = [], []
            for i in range(nclients):
                light = {"id": "share", "type": "point", "intensity": 10.0 + (i if distinct else 0),
                         "position": [0, 1.5, 0]}
                lights.append(light)
                conns.append(self.scene(light=light))
            for c in conns:  # first tick (world creation, shader warm-up) not timed
                self.req(c, lc.TICK, timeout=300)
            s0 = self.stats()
            worlds = s0.get("worlds")
            lat = []
            errors = []
            lock = threading.Lock()
            # the clients move their lights 1 cm in lock-step before each
            # TICK, so every round computes (the planner serves an unchanged
            # world's cached volume): the shared case's clients move theirs
            # to the same place and meet again in one world
            barrier = threading.Barrier(nclients)

            def run(c, light):
                try:
                    for r in range(k):
                        light["position"] = [0.01 * ((r + 1) % 2), 1.5, 0]
                        barrier.wait(300)
                        self.req(c, lc.LIGHT_SET, light)
                        barrier.wait(300)
                        t0 = time.monotonic()
                        self.req(c, lc.TICK, timeout=300)
                        with lock:
                            lat.append(time.monotonic() - t0)
                except Exception as e:
                    with lock:
                        errors.append(str(e))
                    barrier.abort()

            threads = [threading.Thread(target=run, args=(c, li)) for c, li in zip(conns, lights)]
            t0 = time.monotonic()
            for t in threads:
                t.start()
            for t in threads:
                t.join(600)
            dt = time.monotonic() - t0
            s1 = self.stats()
            srv_ticks = (s1.get("ticks") - s0.get("ticks")) if isinstance(s1.get("ticks"), int) and \
                isinstance(s0.get("ticks"), int) else None
            for c in conns:
                c.close()
            rows.append((label, nclients * k, dt, lat, worlds, srv_ticks, errors))
        self.emit("### 5. Sharing: 8 clients on one scene vs 1 (%d TICKs per client, %d^3, 8 iterations, the lights "
                  "moved 1 cm in lock-step before each TICK, so each round computes)" % (k, GRID[0]))
        self.emit()
        self.emit("STATS worlds counts every session's world, including the one of the bench's own STATS "
                  "connection (the default scene); server ticks computed = the change in STATS ticks.")
        self.emit()
        self.emit("| clients | TICK replies | wall (s) | TICK replies/s | TICK p50 (ms) | p99 (ms) | "
                  "STATS worlds | server ticks computed |")
        self.emit("|---|---:|---:|---:|---:|---:|---:|---:|")
        for label, n, dt, lat, worlds, srv, errors in rows:
            self.emit("| %s | %d | %.2f | %.2f | %s | %s | %s | %s |" % (
                label + (" (%d errors)" % len(errors) if errors else ""), n, dt, n / dt, ms(pct(lat, 50)),
                ms(pct(lat, 99)), worlds if worlds is not None else "n/a", srv if srv is not None else "n/a"))
        self.emit()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--unix", help="a running daemon's socket (default: start one)")
    ap.add_argument("--tcp", help="a running daemon's HOST:PORT")
    ap.add_argument("--token")
    ap.add_argument("--lpvd", help="lpvd binary when starting a daemon")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--only", help="comma list of sections 1-5")
    args = ap.parse_args()
    daemon = None
    if args.unix:
        ep = ("unix", args.unix)
    elif args.tcp:
        ep = lc.parse_endpoint(args.tcp)
    else:
        # room for section 4's 64 clients, which connect at once: the
        # defaults let 16 connections wait for their HELLO at a time
        # (--max-preauth) and refuse the rest, the limit that keeps
        # unauthenticated clients from holding the daemon's memory
        daemon = harness.Daemon(harness.find_lpvd(args.lpvd),
                                optional=[("--max-clients", "128"), ("--max-preauth", "128")])
        daemon.start()
        ep = ("unix", daemon.unix)
    b = Bench(ep, args.token, args.quick)
    sections = {"1": b.irradiance, "2": b.latency, "3": b.delta_sizes, "4": b.concurrent, "5": b.sharing}
    only = (args.only or "1,2,3,4,5").split(",")
    try:
        s = b.stats()
        b.emit("## lpvd serve benchmark (%s)" % time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()))
        b.emit()
        b.emit("Daemon: %s; %d CPU cores; %s" % (daemon.binary if daemon else lc.endpoint_str(ep), os.cpu_count(),
                                                "server STATS plan %r" % s.get("plan") if s else "no STATS"))
        b.emit()
        rc = 0
        for k in only:
            try:
                sections[k.strip()]()
            except Exception as e:
                b.emit("Section %s failed: %s: %s" % (k, type(e).__name__, e))
                b.emit()
                rc = 1
    finally:
        if daemon:
            daemon.stop()
    return rc


if __name__ == "__main__":
    sys.exit(main())
