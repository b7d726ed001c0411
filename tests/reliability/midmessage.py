#!/usr/bin/env python3
"""midmessage.py - clients that disconnect mid-message (R2.6) or stall mid-frame (R7.3) while another
client keeps working.

Client B: HELLO, scene, then rounds of TICK + QUERY_IRRADIANCE + GET_VOLUME.
Between B's rounds, client A connects and: sends a header and cuts the body;
sends header + body and cuts the attachment (QUERY_IRRADIANCE, SCENE_LOAD);
sends half a header; or opens a connection that stalls mid-frame and stays
open for the whole run. Checks: every B request answered correctly within
15 s, no reply to any partial frame, the daemon alive, descriptors back to
the baseline (+-2) once the cut connections are gone.
"""

import socket
import struct
import sys
import time

from rel_common import harness, lc, ok, scene_session, percentile, settle

ROUNDS = 12


def cut_variants(token):
    hb = {"version": 1}
    if token:
        hb["token"] = token
    hello_f = lc.encode_frame(lc.HELLO, 1, hb)
    light = lc.encode_frame(lc.LIGHT_SET, 2, {"id": "cut", "type": "point", "intensity": 100.0,
                                              "position": [0, 1, 0]})
    qpts = b"\0" * (5000 * 24)
    query = lc.encode_frame(lc.QUERY_IRRADIANCE, 3, {"count": 5000}, qpts)
    glb = lc.box_scene_glb()
    scene = lc.encode_frame(lc.SCENE_LOAD, 4, {}, glb)
    q_body_end = 24 + len(b'{"count":5000}')
    return [
        ("header sent, body cut", hello_f, light[:24]),
        ("header + part of the body", hello_f, light[:30]),
        ("body sent, attachment cut (query)", hello_f, query[:q_body_end + 777]),
        ("body sent, attachment cut (scene)", hello_f, scene[:len(scene) - 100]),
        ("half a header", hello_f, light[:11]),
        ("no HELLO, header then body cut", b"", light[:26]),
    ]


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    args = ap.parse_args()
    rep = harness.Report("midmessage")
    with harness.Daemon(harness.find_lpvd(args.lpvd)) as d:
        ep = ("unix", d.unix)
        b = scene_session(ep)
        ok(b.request(lc.TICK, {}, timeout=60), lc.TICK, "B first TICK")
        time.sleep(0.3)
        fd0 = d.fd_count()
        stalled = []
        lat = []
        bad = []
        partial_replies = []
        pts = struct.pack("<6f", 0.0, 0.05, 0.0, 0, 1, 0) * 16
        variants = cut_variants(None)
        for rnd in range(ROUNDS):
            name, pre, cut = variants[rnd % len(variants)]
            a = lc.Conn(ep, timeout=10)
            try:
                if pre:
                    a.send_raw(pre)
                    f = a.recv_reply(timeout=10)
                    if f.type != (lc.HELLO | lc.REPLY):
                        bad.append("A HELLO: %r" % f)
                a.send_raw(cut)
                try:
                    f = a.recv(timeout=0.2)
                    partial_replies.append("%s: %r" % (name, f))
                except (socket.timeout, lc.Closed):
                    pass
            finally:
                a.close()
            # every other round, leave a stalled mid-frame connection open
            if rnd % 3 == 0:
                s = lc.Conn(ep, timeout=10)
                s.send_raw(cut[:max(1, len(cut) // 2)])
                stalled.append(s)
            # B keeps working
            for t, body, att in ((lc.TICK, {}, b""), (lc.QUERY_IRRADIANCE, {"count": 16}, pts),
                                 (lc.GET_VOLUME, {"format": "fp32", "compression": "none"}, b"")):
                t0 = time.monotonic()
                try:
                    f = b.request(t, body, att, timeout=15)
                    lat.append(time.monotonic() - t0)
                    if f.type != (t | lc.REPLY):
                        bad.append("round %d %s: %r" % (rnd, lc.type_name(t), f))
                    elif t == lc.QUERY_IRRADIANCE and len(f.att) != 16 * 12:
                        bad.append("round %d query: %d bytes" % (rnd, len(f.att)))
                    elif t == lc.GET_VOLUME and len(f.att) != 16 ** 3 * 48:
                        bad.append("round %d volume: %d bytes" % (rnd, len(f.att)))
                except (socket.timeout, lc.Closed, lc.Violation) as e:
                    bad.append("round %d %s: %s" % (rnd, lc.type_name(t), e))
                    lat.append(15.0)
        rep.check(not bad, "client B served correctly through %d cut clients" % ROUNDS,
                  "; ".join(bad[:5]) if bad else "%d requests, p50 %.3f s, max %.3f s"
                  % (len(lat), percentile(lat, 50), max(lat)))
        rep.check(not partial_replies, "no reply to a partial frame (R2.6)", "; ".join(partial_replies[:3]))
        rep.check(max(lat) < 15.0, "B latency bounded while %d connections stall mid-frame (R7.3)" % len(stalled),
                  "max %.3f s" % max(lat))
        # the stalled ones: B still served, then close them
        t0 = time.monotonic()
        try:
            ok(b.request(lc.STATS, {}, timeout=15), lc.STATS)
            rep.check(True, "STATS with stalled connections open", "%.3f s" % (time.monotonic() - t0))
        except Exception as e:
            rep.check(False, "STATS with stalled connections open", str(e))
        for s in stalled:
            s.close()
        rep.check(d.alive(), "daemon alive")
        fd1 = settle(d.fd_count, fd0, 2)
        rep.check(abs(fd1 - fd0) <= 2, "descriptors back to baseline after the cut clients (+-2)",
                  "%d before, %d after" % (fd0, fd1))
        b.close()
        return rep.finish(d)


if __name__ == "__main__":
    sys.exit(main())
