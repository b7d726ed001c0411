#!/usr/bin/env python3
"""serve_load.py - 50 authenticated clients for 60 s: shared and separate moving worlds (issue 31, load).

Two runs against one `lpvd serve` on TCP loopback with a token, each of
CLIENTS clients (default 50) connecting at once, saying HELLO and loading
the test box, then for SECONDS (default 60) looping TICK, GET_VOLUME (fp16,
zstd) and a one-point QUERY_IRRADIANCE:
  shared    the clients form 5 groups; the clients of a group send the same
            scene, light and settings, so the daemon runs 5 worlds;
  separate  each client moves its own light every loop: 50 worlds, each
            recomputed every tick.
Reported per run: clients admitted, errors, and for each request its p50
and p99 round trip (the issue's bar for the shared case: p99 <= 3 x p50),
and the daemon's VmRSS before the first run and after each; at the end also
its anonymous and file-backed parts (RssAnon; RssFile: the GL driver's and
LLVM's code, paged in at the first tick, and the shader cache's index).

    python3 bench/serve_load.py --lpvd build/server/lpvd [--clients 50] [--seconds 60]
"""

import argparse
import os
import struct
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "tests", "reliability"))

from rel_common import harness, lc, hello, ok  # noqa: E402

KINDS = ("TICK", "GET_VOLUME", "QUERY")
PT = struct.pack("<6f", 0, 0.5, 0, 0, 1, 0)


def pct(v, p):
    s = sorted(v)
    return s[min(len(s) - 1, int(round(p / 100.0 * (len(s) - 1))))] if s else float("nan")


def client(ep, token, i, mode, seconds, glb, start, out):
    times = {k: [] for k in KINDS}
    errors = []
    try:
        c = lc.Conn(ep, timeout=600)
        hello(c, token)
        ok(c.request(lc.SCENE_LOAD, {}, glb, timeout=600), lc.SCENE_LOAD)
        ok(c.request(lc.CONFIG, {"technique": "lpv"}, timeout=60), lc.CONFIG)
        group = i % 5
        ok(c.request(lc.LIGHT_SET, {"id": "l", "type": "point", "intensity": 2.0,
                                    "position": [0.1 * group, 1.0, 0.0]}, timeout=60), lc.LIGHT_SET)
        start.wait()
        t_end = time.monotonic() + seconds
        k = 0
        while time.monotonic() < t_end:
            k += 1
            if mode == "separate":
                ok(c.request(lc.LIGHT_SET, {"id": "l", "type": "point", "intensity": 2.0,
                                            "position": [0.01 * (k % 20), 1.0, 0.02 * i]}, timeout=60), lc.LIGHT_SET)
            for kind, req, body, att in (("TICK", lc.TICK, {}, b""),
                                         ("GET_VOLUME", lc.GET_VOLUME, {"format": "fp16", "compression": "zstd"}, b""),
                                         ("QUERY", lc.QUERY_IRRADIANCE, {"count": 1}, PT)):
                t0 = time.monotonic()
                f = c.request(req, body, att, timeout=600)
                if f.type != (req | lc.REPLY):
                    errors.append("%s: %r" % (kind, f)[:200])
                    continue
                times[kind].append((time.monotonic() - t0) * 1000.0)
        c.close()
    except Exception as e:
        errors.append(repr(e)[:200])
    out[i] = (times, errors)


def run(d, mode, clients, seconds, glb):
    ep = d.tcp
    start = threading.Event()
    out = {}
    ts = [threading.Thread(target=client, args=(ep, d.token, i, mode, seconds, glb, start, out))
          for i in range(clients)]
    for t in ts:
        t.start()
    time.sleep(5.0)  # connected, loaded
    start.set()
    for t in ts:
        t.join(seconds + 600)
    errors = [e for v in out.values() for e in v[1]]
    admitted = sum(1 for v in out.values() if not any("HELLO" in e or "LIMIT" in e for e in v[1]))
    stats = {}
    for k in KINDS:
        v = [x for r in out.values() for x in r[0][k]]
        stats[k] = (len(v), pct(v, 50), pct(v, 99))
    return admitted, errors, stats


def rss_parts(pid):
    """(RssAnon, RssFile + RssShmem) in KiB: what the daemon allocated, and the pages of files it maps."""
    v = {}
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            k, _, rest = line.partition(":")
            if k in ("RssAnon", "RssFile", "RssShmem"):
                v[k] = int(rest.split()[0])
    return v.get("RssAnon", 0), v.get("RssFile", 0) + v.get("RssShmem", 0)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--lpvd", required=True)
    ap.add_argument("--clients", type=int, default=50)
    ap.add_argument("--seconds", type=float, default=60.0)
    a = ap.parse_args()
    glb = lc.box_scene_glb()
    with harness.Daemon(os.path.abspath(a.lpvd), tcp=True, token=True, quiet=True) as d:
        time.sleep(0.5)
        rss0 = d.rss_kib()
        parts0 = rss_parts(d.proc.pid)
        print("VmRSS before: %.1f MiB" % (rss0 / 1024.0), flush=True)
        print("| run | admitted | errors | TICK n / p50 / p99 ms | GET_VOLUME n / p50 / p99 ms | "
              "QUERY n / p50 / p99 ms | VmRSS after MiB |")
        print("| --- | ---: | ---: | --- | --- | --- | ---: |")
        for mode in ("shared", "separate"):
            admitted, errors, st = run(d, mode, a.clients, a.seconds, glb)
            time.sleep(2.0)
            cells = ["%d / %.0f / %.0f" % st[k] for k in KINDS]
            print("| %s | %d of %d | %d | %s | %.1f |" % (mode, admitted, a.clients, len(errors), " | ".join(cells),
                                                        d.rss_kib() / 1024.0), flush=True)
            for e in errors[:3]:
                print("  error: %s" % e)
        print("VmRSS after both: %.1f MiB (%+.1f %% of before)" %
              (d.rss_kib() / 1024.0, 100.0 * (d.rss_kib() - rss0) / rss0))
        parts1 = rss_parts(d.proc.pid)
        print("of which: anonymous %.1f -> %.1f MiB (%+.1f %%), file-backed (library code paged in, the shader "
              "cache's index) %.1f -> %.1f MiB" % (parts0[0] / 1024.0, parts1[0] / 1024.0,
                                                  100.0 * (parts1[0] - parts0[0]) / parts0[0],
                                                  parts0[1] / 1024.0, parts1[1] / 1024.0))
    return 0


if __name__ == "__main__":
    sys.exit(main())
