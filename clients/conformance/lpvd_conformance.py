#!/usr/bin/env python3
"""lpvd_conformance.py - conformance suite for the lpvd wire protocol, version 1.

Checks a running server against protocol/SPEC.md by sending real bytes (frames
built with struct, well-formed and malformed) and comparing the replies, the
closes and the payloads with what the SPEC requires. Every case names the
requirement numbers (R2.2, ...) it checks. Pure standard library.

    lpvd_conformance.py --unix /tmp/lpvd.sock
    lpvd_conformance.py --tcp 127.0.0.1:7070 --token SECRET --junit out.xml
    lpvd_conformance.py --unix S --tcp H:P --token T --scene-root DIR --idle-timeout 4
    lpvd_conformance.py --unix S --only R2.2,R4.7      (cases citing R2.2 or R4.7; "R2" = all of section 2)
    lpvd_conformance.py --list

Output: one verdict line per case (PASS/FAIL/SKIP, requirements, what), then
a closing line exactly "N passed, M failed". Exit status 0 only when nothing
failed. SKIP is only used for cases whose pre-condition is a command-line
option that was not given (--token, --scene-root, --idle-timeout); they are
not counted as passed.

This file is the entry point: the command line, the runner and the JUnit
writer. The rest lives in the modules next to it (standard library only):

    conf_wire           message types, error codes, frames, Conn (the client)
    conf_payloads       volume/frame bytes, zstd headers, glb and PNG builders, SMALL_CONFIG
    conf_core           the case registry (@case, CASES), Fail/Skip, reply checks, Ctx
    conf_volume_checks  volume header, "volume" description and plan checks, R5.14's and R5.15's lookups

and the cases, imported below in the order they run:

    conf_handshake      transport and handshake (R1.1, R2.1, R4.1)
    conf_malformed      malformed frames and bodies (R2.2 - R2.9)
    conf_replies        replies, ordering, revisions, ERROR bodies (R3)
    conf_tokens         tokens (R1.2, R4.2)
    conf_scenes         scene paths, glb attachments, images (R4.3 - R4.5b)
    conf_config         CONFIG limits, presets, techniques, knobs (R4.6, R4.10 - R4.15)
    conf_queries        QUERY_IRRADIANCE (R4.7), settings at the limits (R7.6)
    conf_volumes        GET_VOLUME (R5.1 - R5.15)
    conf_streams        VOLUME streams and deltas (R5.1 - R5.3)
    conf_frame_stats    GET_FRAME, STATS, the tick plan (R6.1, R6.2, R3.1, R7.6a, R8)
    conf_limits         BYE, idle and handshake timeouts, server limits (R4.8, R4.9, R4.1a, R4.5)
    conf_updates        SCENE_UPDATE, CAMERA_SET (R3.3, R4.4c)
    conf_frames         FRAME streams, exr, the ao term (R6.1 - R6.5)
    conf_sessions       sessions with identical inputs (R7.1, R7.2)

The module doubles as a small client library (Conn, encode_frame, make_glb,
...), re-exported here from conf_wire, conf_payloads and conf_core, used by
tests/reliability/ and bench/serve_bench.py (import lpvd_conformance as lc).
"""

import argparse
import os
import socket
import sys
import time
import xml.etree.ElementTree as ET

# The client library and the case machinery, re-exported so that lc.Conn,
# lc.HELLO, lc.box_scene_glb, lc.struct, ... work as they did before the split.
from conf_wire import *  # noqa: F401,F403
from conf_payloads import *  # noqa: F401,F403
from conf_core import *  # noqa: F401,F403
from conf_wire import Closed, Violation
from conf_core import CASES, Ctx, Fail, Skip

# The cases. Each import registers its module's cases in conf_core.CASES: the
# order of these imports is the order the cases run in and --list shows them.
import conf_handshake  # noqa: F401
import conf_malformed  # noqa: F401
import conf_replies  # noqa: F401
import conf_tokens  # noqa: F401
import conf_scenes  # noqa: F401
import conf_config  # noqa: F401
import conf_queries  # noqa: F401
import conf_volumes  # noqa: F401
import conf_streams  # noqa: F401
import conf_frame_stats  # noqa: F401
import conf_limits  # noqa: F401
import conf_updates  # noqa: F401
import conf_frames  # noqa: F401
import conf_sessions  # noqa: F401


# ---------------------------------------------------------------------------
# Runner


def select(cases, only):
    if not only:
        return cases
    wanted = [w.strip() for w in only.split(",") if w.strip()]
    out = []
    for cs in cases:
        if any(r == w or r.startswith(w + ".") for r in cs["reqs"] for w in wanted):
            out.append(cs)
    return out


def write_junit(path, results, total_time):
    suite = ET.Element("testsuite", name="lpvd-conformance", tests=str(len(results)),
                       failures=str(sum(1 for r in results if r["verdict"] == "FAIL")),
                       skipped=str(sum(1 for r in results if r["verdict"] == "SKIP")),
                       errors="0", time="%.3f" % total_time)
    for r in results:
        tc = ET.SubElement(suite, "testcase", classname="lpvd.conformance." + r["reqs"][0],
                           name="%s %s" % ("/".join(r["reqs"]), r["title"]), time="%.3f" % r["time"])
        if r["verdict"] == "FAIL":
            ET.SubElement(tc, "failure", message=r["reason"][:500]).text = r["reason"]
        elif r["verdict"] == "SKIP":
            ET.SubElement(tc, "skipped", message=r["reason"])
        else:
            ET.SubElement(tc, "system-out").text = r["reason"]
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    ET.ElementTree(suite).write(path, encoding="utf-8", xml_declaration=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description="lpvd protocol v1 conformance suite (protocol/SPEC.md)")
    ap.add_argument("--unix", metavar="PATH", help="server's Unix socket")
    ap.add_argument("--tcp", metavar="HOST:PORT", help="server's TCP address")
    ap.add_argument("--token", help="the server's token (it has one configured); enables the token cases")
    ap.add_argument("--scene-root", metavar="DIR", help="the server's --scene-root, writable by this suite "
                    "(enables the symlink and load-by-path cases)")
    ap.add_argument("--idle-timeout", type=float, metavar="S", help="the server's --idle-timeout (enables R4.9)")
    ap.add_argument("--junit", metavar="OUT.xml", help="write JUnit XML")
    ap.add_argument("--only", metavar="R2.2,...", help="only cases citing these requirements (R2 = section 2)")
    ap.add_argument("--timeout", type=float, default=10.0, help="seconds to wait for an ordinary reply")
    ap.add_argument("--tick-timeout", type=float, default=60.0, help="seconds to wait for a tick or scene load")
    ap.add_argument("--list", action="store_true", help="list the cases and exit")
    args = ap.parse_args(argv)

    if args.list:
        for cs in CASES:
            print("%-14s %s" % (" ".join(cs["reqs"]), cs["title"]))
        return 0
    if not args.unix and not args.tcp:
        ap.error("give --unix PATH and/or --tcp HOST:PORT")
    ctx = Ctx(args)
    cases = select(CASES, args.only)
    if not cases:
        ap.error("--only %s selects no case" % args.only)
    results = []
    t_all = time.monotonic()
    for cs in cases:
        t0 = time.monotonic()
        verdict, reason = "PASS", ""
        try:
            reason = cs["fn"](ctx) or ""
        except Fail as e:
            verdict, reason = "FAIL", str(e)
        except Skip as e:
            verdict, reason = "SKIP", str(e)
        except Closed as e:
            verdict, reason = "FAIL", "unexpected close: %s" % e
        except socket.timeout:
            verdict, reason = "FAIL", "timed out waiting for the server"
        except Violation as e:
            verdict, reason = "FAIL", "malformed server frame: %s" % e
        except (ConnectionRefusedError, FileNotFoundError) as e:
            verdict, reason = "FAIL", "cannot connect: %s" % e
        except OSError as e:
            verdict, reason = "FAIL", "socket error: %s" % e
        except Exception as e:  # a bug in the case or a reply of a shape the case did not expect
            verdict, reason = "FAIL", "%s: %s" % (type(e).__name__, e)
        finally:
            ctx.close_all()
        dt = time.monotonic() - t0
        results.append({"reqs": cs["reqs"], "title": cs["title"], "verdict": verdict, "reason": reason, "time": dt})
        print("%s %-12s %s%s" % (verdict, "/".join(cs["reqs"]), cs["title"],
                                 (" -- " + reason) if reason else ""), flush=True)
    total = time.monotonic() - t_all
    npass = sum(1 for r in results if r["verdict"] == "PASS")
    nfail = sum(1 for r in results if r["verdict"] == "FAIL")
    nskip = sum(1 for r in results if r["verdict"] == "SKIP")
    if args.junit:
        write_junit(args.junit, results, total)
    if nskip:
        print("%d skipped (pre-conditions not given on the command line; not counted as passed)" % nskip)
    print("%d passed, %d failed" % (npass, nfail))
    return 1 if nfail else 0


if __name__ == "__main__":
    sys.exit(main())
