#!/usr/bin/env python3
"""shq_keyframes.py - a delta stream sends a keyframe where that is smaller (issue 35, SPEC R5.16).

A keyframe's cells are predicted from each other (R5.16 flag bit 1), so once
a light moves far, re-sending most cells as a delta costs more than a new
keyframe. lpvd tries the keyframe when a delta re-sends more than a quarter
of the cells and sends the smaller (before: a keyframe only past 15/16 of
them).

One session subscribes to shq deltas (e = 0.01) of the test box and ACKs
every VOLUME:
1. after the first keyframe, a 1 cm light move gives a delta, smaller than
   the keyframe;
2. moving the light across the box moves most cells past the bound but
   not 15/16 of them (counted against the client's held volume with
   GET_VOLUME fp32 of the new tick): lpvd sends a keyframe, with the
   predicted flag, the smaller (the rule before sent a delta);
3. every volume the client rebuilds is within the bound of its tick.
"""

import os
import sys

from rel_common import harness, lc, ok, shq_subscribe, shq_tick

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                                "clients", "python"))
import lpvd_volume as lv  # noqa: E402
from lpvd_protocol import _zstd_decompress  # noqa: E402

BOUND = 0.01
CONFIG = {"technique": "lpv", "grid": [32, 32, 32], "cascades": 1, "rsm_size": 128}
LIGHT = {"id": "key", "type": "point", "intensity": 4.0, "position": [-0.6, 1.2, -0.4]}


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    args = ap.parse_args()
    rep = harness.Report("shq_keyframes")
    lpvd = harness.find_lpvd(args.lpvd)
    with harness.Daemon(lpvd, quiet=True) as d:
        c = shq_subscribe(("unix", d.unix), CONFIG, LIGHT, BOUND)
        held, seen = None, []
        for step, pos in enumerate(([-0.6, 1.2, -0.4], [-0.59, 1.2, -0.4], [0.6, 0.5, 0.4])):
            if step:
                ok(c.request(lc.LIGHT_SET, dict(LIGHT, position=pos), timeout=60), lc.LIGHT_SET)
            v, held, _, cells, worst, moved = shq_tick(c, held, BOUND)
            _, extra = lv.shq_cells(v.body)
            flags = int.from_bytes(_zstd_decompress(v.att, lv.shq_payload_max(cells, extra))[4:8], "little")
            seen.append((v.body["keyframe"], flags, len(v.att), moved, cells, worst))
        rep.check(seen[0][0] and seen[0][1] == 3, "the first VOLUME is a predicted keyframe (flags 3)",
                  "keyframe %r, flags %d, %d bytes" % seen[0][:3])
        rep.check(seen[1][0] is False and 0 < seen[1][3] < seen[1][4] and seen[1][2] < seen[0][2],
                  "a 1 cm move gives a delta, smaller than the keyframe",
                  "keyframe %r, %d of %d cells past the bound, %d bytes (keyframe %d)" % (
                      seen[1][0], seen[1][3], seen[1][4], seen[1][2], seen[0][2]))
        key, flags, size, moved, cells, _ = seen[2]
        rep.check(key and flags == 3 and cells // 4 < moved < cells - cells // 16,
                  "a move across the box re-sends most cells but not 15/16: a keyframe, the smaller",
                  "keyframe %r, flags %d, %d of %d cells past the bound, %d bytes" % (key, flags, moved, cells, size))
        rep.check(all(s[5] <= BOUND * (1 + 1e-6) for s in seen), "every rebuilt volume is within the bound",
                  "worst D/M %r" % [round(s[5], 5) for s in seen])
        c.close()
        rep.check(d.alive(), "the daemon is alive")
    return rep.finish()


if __name__ == "__main__":
    sys.exit(main())
