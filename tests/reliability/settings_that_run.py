#!/usr/bin/env python3
"""settings_that_run.py - what HELLO advertises and CONFIG accepts can run (R4.6, R7.6).

Issue 31, item 11: settings were accepted that could never tick. Against one
daemon at the default limits:
  1. HELLO's limits.max_grid is a grid one world can hold: the test box (one
     point light) at grid max_grid, one cascade, no far field, no normal bins,
     one iteration, ticks; max_grid + 1 is refused at CONFIG.
  2. A grid whose LPV storage alone is over --max-world-memory (the
     advertised maximum with three explicit cascades) is refused at CONFIG
     with LIMIT naming --max-world-memory, not at every tick.
  3. rsm_size 2048 in a scene whose light faces need a VPL buffer over what
     one shader storage buffer holds (the built-in box: a point light and its
     area light samples) is refused at TICK with LIMIT naming rsm_size (it
     was INTERNAL), and the session ticks again after a smaller rsm_size.
  4. A camera whose frame one world can never hold (4096 x 4096 under the
     default 1 GiB) is refused at CAMERA_SET with LIMIT, not at every tick.
"""

import sys

from rel_common import harness, lc, ok, hello, scene_session

SIMPLE = {"technique": "lpv", "cascades": 1, "far_field": False, "normal_bins": False, "iterations": 1,
          "area_lights": False}


def err_of(f):
    return "%s: %s" % (f.err_name, f.body.get("message", "")) if f.type == lc.ERROR else "reply %r" % f.type


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    args = ap.parse_args()
    rep = harness.Report("settings_that_run")
    with harness.Daemon(harness.find_lpvd(args.lpvd)) as d:
        ep = ("unix", d.unix)
        c = lc.Conn(ep, timeout=300)
        lim = hello(c).body["limits"]
        mg = lim["max_grid"]
        ok(c.request(lc.SCENE_LOAD, {}, lc.box_scene_glb(), timeout=120), lc.SCENE_LOAD)
        f = c.request(lc.CONFIG, dict(SIMPLE, grid=[mg, mg, mg]), timeout=120)
        rep.check(f.type == (lc.CONFIG | lc.REPLY), "CONFIG at the advertised max_grid %d is accepted" % mg, err_of(f))
        f = c.request(lc.TICK, {}, timeout=300)
        rep.check(f.type == (lc.TICK | lc.REPLY), "and ticks (one light, one cascade)", err_of(f))
        f = c.request(lc.CONFIG, dict(SIMPLE, grid=[mg + 1] * 3), timeout=60)
        rep.check(f.type == lc.ERROR and f.err_name in ("LIMIT", "BAD_FIELD"), "max_grid + 1 is refused at CONFIG",
                  err_of(f))
        f = c.request(lc.CONFIG, dict(SIMPLE, grid=[mg] * 3, cascades=3), timeout=60)
        rep.check(f.type == lc.ERROR and f.err_name == "LIMIT" and "--max-world-memory" in err_of(f),
                  "three cascades of it are refused at CONFIG, naming --max-world-memory", err_of(f))
        c.close()

        b = lc.Conn(ep, timeout=300)
        hello(b)  # the built-in box
        ok(b.request(lc.CONFIG, {"rsm_size": 2048}, timeout=60), lc.CONFIG)
        f = b.request(lc.TICK, {}, timeout=300)
        rep.check(f.type == lc.ERROR and f.err_name == "LIMIT" and "rsm_size" in err_of(f),
                  "rsm_size 2048 with the box's light faces: TICK gets LIMIT naming rsm_size", err_of(f))
        ok(b.request(lc.CONFIG, {"rsm_size": 256}, timeout=60), lc.CONFIG)
        f = b.request(lc.TICK, {}, timeout=300)
        rep.check(f.type == (lc.TICK | lc.REPLY), "then rsm_size 256 ticks", err_of(f))
        f = b.request(lc.CAMERA_SET, {"eye": [0, 1, 3], "target": [0, 1, 0], "width": 4096, "height": 4096})
        rep.check(f.type == lc.ERROR and f.err_name == "LIMIT" and "image size" in err_of(f),
                  "a 4096x4096 camera is refused at CAMERA_SET with LIMIT", err_of(f))
        f = b.request(lc.TICK, {}, timeout=300)
        rep.check(f.type == (lc.TICK | lc.REPLY), "and the session ticks on", err_of(f))
        b.close()
        rep.check(d.alive(), "daemon alive")
        return rep.finish(d)


if __name__ == "__main__":
    sys.exit(main())
