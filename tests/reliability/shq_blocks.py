#!/usr/bin/env python3
"""shq_blocks.py - a delta moves the client's cells by blocks where that is smaller (issue 35, SPEC R5.16 bit 2).

Light that changes smoothly across cells (a lamp moving 1 cm, injected with
smooth_injection) leaves most cells past the bound, but by nearly the same
amount as their neighbours: one change per block of 3 x 3 x 3 cells carries
it, and only the cells the blocks leave past the bound are re-sent.

One session subscribes to shq deltas (e = 0.01) of the test box with smooth
injection and ACKs every VOLUME while the light moves 1 cm per TICK:
1. the deltas carry blocks (flag bit 2) and re-send fewer cells than were
   past the bound before them (counted against the client's held volume
   with GET_VOLUME fp32 of the new tick);
2. the Python client's decoders (numpy and the standard library) and the
   conformance suite's own decoder (exact rationals) rebuild the same bytes;
3. every volume the client rebuilds is within the bound of its tick.
"""

import os
import struct
import sys

from rel_common import harness, lc, ok, shq_subscribe, shq_tick

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
sys.path.insert(0, os.path.join(ROOT, "clients", "conformance"))
import lpvd_volume as lv  # noqa: E402
from lpvd_protocol import _zstd_decompress  # noqa: E402
from conf_volume_checks import _shq_decode as conformance_decode  # noqa: E402

BOUND = 0.01
CONFIG = {"technique": "lpv", "grid": [24, 24, 24], "cascades": 1, "rsm_size": 128, "smooth_injection": True}
LIGHT = {"id": "blk", "type": "point", "intensity": 4.0, "position": [0.0, 1.2, 0.0]}
STEPS = 4


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    args = ap.parse_args()
    rep = harness.Report("shq_blocks")
    lpvd = harness.find_lpvd(args.lpvd)
    with harness.Daemon(lpvd, quiet=True) as d:
        c = shq_subscribe(("unix", d.unix), CONFIG, LIGHT, BOUND)
        held, seen, same = None, [], []
        for step in range(STEPS + 1):
            before = held
            if step:
                ok(c.request(lc.LIGHT_SET, dict(LIGHT, position=[0.01 * step, 1.2, 0.0]), timeout=60), lc.LIGHT_SET)
            v, held, _, cells, worst, moved = shq_tick(c, before, BOUND)
            np_ = lv._np
            try:
                lv._np = None
                plain = lv.shq_decode(v.att, v.body, before)
            finally:
                lv._np = np_
            _, extra = lv.shq_cells(v.body)
            payload = _zstd_decompress(v.att, lv.shq_payload_max(cells, extra))
            exact_rat, sent = conformance_decode(v.body, payload, before)
            same.append(held == plain == exact_rat)
            flags = struct.unpack_from("<I", payload, 4)[0]
            seen.append((v.body["keyframe"], flags, len(v.att), moved, sent, worst))
        deltas = seen[1:]
        blocks = [s for s in deltas if not s[0] and s[1] == 4]
        rep.check(len(blocks) >= STEPS // 2, "the deltas of a smoothly moving light carry blocks (flag bit 2)",
                  "%d of %d: %s" % (len(blocks), len(deltas), ", ".join(
                      "flags %d, %d bytes, %r cells past the bound, %d re-sent" % s[1:5] for s in deltas)))
        rep.check(bool(blocks) and all(s[4] < s[3] for s in blocks),
                  "with blocks, fewer cells are re-sent than were past the bound",
                  "; ".join("%d past, %d re-sent" % (s[3], s[4]) for s in blocks))
        rep.check(all(same), "numpy, the standard library and the conformance decoder rebuild the same bytes",
                  "%r" % same)
        rep.check(all(s[5] <= BOUND * (1 + 1e-6) for s in seen), "every rebuilt volume is within the bound",
                  "worst D/M %r" % [round(s[5], 5) for s in seen])
        c.close()
        rep.check(d.alive(), "the daemon is alive")
    return rep.finish()


if __name__ == "__main__":
    sys.exit(main())
