#!/usr/bin/env python3
"""shared_bases.py - the volumes delta subscribers hold: one copy however many hold it, counted, and given back (issue 35).

A delta subscriber's server side keeps the volume the client holds (the one
it ACKed, and those sent that it may ACK): an shq reconstruction or a packed
XOR base, 2.4-4.7 MB each at 3 x 32^3. Before, every subscriber kept a copy
of its own, even when subscribers of one world in step held the same bytes
(50 of them: 50 copies, 18-24 ms of fresh-page writes each per update on
the 2-core machine), and none of it was in the daemon's memory budget
(R7.6a). Now subscribers that hold the same volume share one
reference-counted copy, and STATS memory.bases counts each copy once.

1. Three sessions of one world subscribe to shq deltas; after the keyframe
   and two light moves in lock-step (every VOLUME after the first a delta,
   none a keyframe), memory.bases is at most twice one volume's raw_length
   (the ACKed volume and one in flight), not three subscribers' worth.
2. Two more sessions, of a world of their own, subscribe to fp16 + zstd
   XOR deltas: after a keyframe and a light move in lock-step (a delta),
   bases settles at what it was plus one packed fp16 volume: the two hold
   one copy (counted too); both rebuild the tick's volume byte for byte
   (GET_VOLUME fp16 of the same tick).
3. When every subscriber has gone (and so have the worlds and their cached
   encodings), a new session's STATS says bases 0 and encodings 0: no
   reference kept, the counts given back exactly. While they lived, the
   encodings their results kept for the next subscriber (memory.encodings)
   were counted: more than 0, at most 8 attachments (4 shared encodings
   and 4 keyframes a result).
4. The bases are within the budget: a daemon whose --max-memory leaves the
   bases room for one and a half volumes beside its world does not keep a
   second (STATS encode.bases_refused counts it); the subscriber gets a
   keyframe instead of a delta against what it was not kept, every TICK
   is answered, and the bases and the cached encodings together never pass
   their room.
"""

import os
import sys

from rel_common import harness, lc, ok, scene_session, settle

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                                "clients", "python"))
from lpvd_protocol import _zstd_decompress  # noqa: E402

MIB = 1 << 20
LIGHT = {"id": "key", "type": "point", "intensity": 4.0, "position": [0.0, 1.2, 0.0]}
SHQ = {"stream": "volume", "compression": "shq", "error_bound": 0.01, "delta": True}


def stats(c):
    return ok(c.request(lc.STATS, {}, timeout=120), lc.STATS).body


def drain(c, seen, timeout, atts=None):
    """Every VOLUME that comes within timeout, ACKed; their headers appended to seen (attachments to atts)."""
    while True:
        try:
            m = c.recv_stream(lc.VOLUME, timeout=timeout)
        except Exception:  # socket.timeout: nothing more
            return
        seen.append(m.body)
        if atts is not None:
            atts.append(bytes(m.att))
        c.send(lc.ACK, {"stream": "volume", "tick": m.body["tick"]})
        timeout = min(timeout, 3.0)


def over_budget(rep, lpvd, world, scenes, raw_len):
    """Part 4: room for one and a half volumes beside the world."""
    budget = 16 * MIB + world + scenes + raw_len * 3 // 2
    with harness.Daemon(lpvd, quiet=True, extra=["--max-message", str(16 * MIB), "--max-memory", str(budget)]) as d:
        c = scene_session(("unix", d.unix), light=dict(LIGHT), timeout=120)
        ok(c.request(lc.SUBSCRIBE, SHQ, timeout=60), lc.SUBSCRIBE)
        seen, ticks, most = [], [], 0
        for step in range(4):
            if step:
                ok(c.request(lc.LIGHT_SET, dict(LIGHT, position=[0.05 * step, 1.2, 0.0]), timeout=60), lc.LIGHT_SET)
            f = c.request(lc.TICK, {}, timeout=300)
            ticks.append(f.type == (lc.TICK | lc.REPLY) or f.body.get("message", "?"))
            drain(c, seen, 30.0)  # the VOLUME is sent before its base is kept or refused
            m = stats(c)["memory"]
            most = max(most, m["bases"] + m.get("encodings", 0))
        refused = stats(c)["encode"].get("bases_refused", 0)
        acked = set()
        chained = True
        for h in seen:  # every delta is against a volume the client ACKed
            chained = chained and (h["keyframe"] or h.get("base_tick") in acked)
            acked.add(h["tick"])
        rep.check(all(t is True for t in ticks) and len(seen) == 4, "every TICK is answered and streams a VOLUME",
                  "TICKs %r, VOLUMEs %d" % (ticks, len(seen)))
        rep.check(refused >= 1 and chained and sum(1 for h in seen if h["keyframe"]) >= 2,
                  "over the budget a second base is not kept: a keyframe follows, every delta's base was ACKed",
                  "bases_refused %d, keyframes %r" % (refused, [h["keyframe"] for h in seen]))
        rep.check(most <= raw_len * 3 // 2, "the bases and the cached encodings never pass their room",
                  "at most %d bytes after a VOLUME, room %d" % (most, raw_len * 3 // 2))
        c.close()
        rep.check(d.alive(), "the daemon is alive")


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    args = ap.parse_args()
    rep = harness.Report("shared_bases")
    lpvd = harness.find_lpvd(args.lpvd)
    with harness.Daemon(lpvd, quiet=True) as d:
        ep = ("unix", d.unix)
        subs = [scene_session(ep, light=dict(LIGHT), timeout=120) for _ in range(3)]
        seen = [[] for _ in subs]
        atts = [[] for _ in subs]
        for c in subs:
            ok(c.request(lc.SUBSCRIBE, SHQ, timeout=60), lc.SUBSCRIBE)
        ok(subs[0].request(lc.TICK, {}, timeout=300), lc.TICK)
        for c, s in zip(subs, seen):
            drain(c, s, 30.0)
        first = stats(subs[0])
        world, scenes = first["memory"]["worlds"], first["memory"]["scenes"]
        rep.check(stats(subs[0]).get("world_sessions") == 3, "the three sessions share one world",
                  "world_sessions %r" % stats(subs[0]).get("world_sessions"))
        for step in (1, 2):
            light = dict(LIGHT, position=[0.05 * step, 1.2, 0.0])
            for c in subs:
                ok(c.request(lc.LIGHT_SET, light, timeout=60), lc.LIGHT_SET)
            ok(subs[0].request(lc.TICK, {}, timeout=300), lc.TICK)
            for c, s, a in zip(subs, seen, atts):
                drain(c, s, 30.0, a)
        raw_len = max((h["raw_length"] for s in seen for h in s), default=0)
        keyframes = [sum(1 for h in s if h["keyframe"]) for s in seen]
        counts = [len(s) for s in seen]
        rep.check(all(n >= 3 for n in counts) and all(k == 1 for k in keyframes),
                  "each subscriber gets a keyframe, then deltas for both moves",
                  "VOLUMEs %r, keyframes %r" % (counts, keyframes))
        s = stats(subs[0])
        bases = s.get("memory", {}).get("bases")
        rep.check(bases is not None and raw_len > 0 and raw_len <= bases <= 2 * raw_len,
                  "three subscribers in step hold one shared volume: memory.bases within 1-2 raw volumes",
                  "bases %r bytes, one volume %d bytes (unshared: at least %d)" % (bases, raw_len, 3 * raw_len))
        encodings = s.get("memory", {}).get("encodings")
        att_max = max((len(a) for x in atts for a in x), default=0)
        rep.check(isinstance(encodings, int) and 0 < encodings <= 8 * att_max,
                  "the encodings the tick's result keeps for the next subscriber are counted (memory.encodings)",
                  "encodings %r bytes, the largest attachment %d bytes" % (encodings, att_max))

        own = dict(LIGHT, id="own")
        xors = [scene_session(ep, light=own, timeout=120) for _ in range(2)]
        xs = [[] for _ in xors]
        xa = [[] for _ in xors]
        for c in xors:
            ok(c.request(lc.SUBSCRIBE, {"stream": "volume", "format": "fp16", "compression": "zstd", "delta": True},
                         timeout=60), lc.SUBSCRIBE)
        for step in (0, 1):
            if step:
                for c in xors:
                    ok(c.request(lc.LIGHT_SET, dict(own, position=[0.0, 1.1, 0.05]), timeout=60), lc.LIGHT_SET)
            ok(xors[0].request(lc.TICK, {}, timeout=300), lc.TICK)
            for c, x, a in zip(xors, xs, xa):
                drain(c, x, 30.0, a)
        fp16_len = xs[0][0]["raw_length"] if xs[0] else 0
        after = settle(lambda: stats(xors[0]).get("memory", {}).get("bases", 0), (bases or 0) + fp16_len, 0,
                       timeout=20.0)
        rep.check(fp16_len > 0 and [[h["keyframe"] for h in x] for x in xs] == [[True, False]] * 2 and
                  after == (bases or 0) + fp16_len,
                  "two fp16 XOR subscribers in step hold one copy of their base, counted",
                  "bases %d -> %d, one packed volume %d bytes, keyframes %r" % (
                      bases or 0, after, fp16_len, [[h["keyframe"] for h in x] for x in xs]))

        exact = ok(xors[0].request(lc.GET_VOLUME, {"format": "fp16", "compression": "none"}, timeout=120),
                   lc.GET_VOLUME)
        rebuilt = []
        for x, a in zip(xs, xa):
            vol = None
            for h, att in zip(x, a):
                raw = _zstd_decompress(att, h["raw_length"])
                vol = raw if h["keyframe"] else bytes(p ^ q for p, q in zip(raw, vol))
            rebuilt.append((x[-1]["tick"] if x else None, vol))
        rep.check(all(t == exact.body.get("tick") and v == bytes(exact.att) for t, v in rebuilt),
                  "both XOR subscribers rebuild the tick's volume byte for byte",
                  "ticks %r, GET_VOLUME tick %r" % ([t for t, _ in rebuilt], exact.body.get("tick")))

        for c in subs + xors:
            c.close()
        fresh = scene_session(ep, timeout=120)
        left = settle(lambda: stats(fresh).get("memory", {}).get("bases", -1), 0, 0, timeout=20.0)
        rep.check(left == 0, "every subscriber gone: memory.bases is 0 (no reference kept)", "bases %r" % left)
        enc_left = settle(lambda: stats(fresh).get("memory", {}).get("encodings", -1), 0, 0, timeout=20.0)
        rep.check(enc_left == 0, "every world gone: memory.encodings is 0 (every cache given back)",
                  "encodings %r" % enc_left)
        fresh.close()
        rep.check(d.alive(), "the daemon is alive")
    over_budget(rep, lpvd, world, scenes, raw_len)
    return rep.finish()


if __name__ == "__main__":
    sys.exit(main())
