#!/usr/bin/env python3
"""preauth.py - nothing before HELLO but HELLO (issue 14, item 1; SPEC R2.5a, R4.1a, R4.9).

Hostile clients that never authenticate, against a TCP listener with a token:

1. memory: two clients each declare a 250 MiB attachment and send it. Before,
   the daemon read both (peak RSS +750 MB) and only then said HELLO_REQUIRED.
   Expected: ERROR TOO_LARGE naming --max-preauth-body from the header alone,
   then close; the daemon's peak RSS (VmHWM) grows by at most 64 MiB (the
   fixed daemon reads nothing of the attachments: 0 to a few MiB measured).
   A 1-byte attachment is refused the same way; HELLO and a SCENE_LOAD with a
   glb attachment pipelined in one write both succeed.
2. replies before HELLO: a client sending 20000 small frames before HELLO and
   reading nothing is dropped at the pre-auth reply cap (64 KiB queued)
   instead of getting all 20000 HELLO_REQUIRED errors queued.
3. slots: with --max-clients 4, 8 connections trickling one byte every 2 s
   (never a whole frame) do not keep a client with the right token out; a
   connection over --max-preauth is let in and the oldest connection waiting
   for HELLO gets ERROR LIMIT naming it and is closed (before: the newcomer
   was refused, so 16 connections held open kept every client out);
   with 4 sessions open a fifth right HELLO gets LIMIT (naming --max-clients,
   the HELLO's request_id) and is closed.
4. deadline: a silent connection, and one trickling bytes, are sent ERROR
   LIMIT naming --handshake-timeout and closed (--handshake-timeout 2; bound
   20 s, 10x).
5. idle: a session sending one byte every 0.5 s of a frame it never completes
   is sent BYE by the idle timer (--idle-timeout 3; bound 30 s, 10x).
"""

import os
import socket
import sys
import threading
import time

from rel_common import harness, lc, hello, ok

BIG = 250 << 20


def hwm_kib(d):
    with open("/proc/%d/status" % d.pid) as fh:
        for line in fh:
            if line.startswith("VmHWM:"):
                return int(line.split()[1])
    return 0


def refused_at_header(rep, ep, att_len, what):
    """Sends a header declaring att_len bytes of attachment before HELLO, waits for the ERROR before
    sending the body, then sends the body anyway (in a thread: a server that waits for it reads it)."""
    c = lc.Conn(ep, timeout=30)
    c.send_raw(lc.HEADER.pack(lc.MAGIC, lc.VERSION, lc.SCENE_LOAD, 5, 0, 2, att_len))
    got = [None]
    try:
        got[0] = c.recv_reply(timeout=3)
    except (socket.timeout, lc.Closed) as e:
        got[0] = e

    def push():
        try:
            c.sock.settimeout(60)
            c.sock.sendall(b"{}")
            chunk = b"\0" * (1 << 20)
            left = att_len
            while left > 0:
                n = min(left, len(chunk))
                c.sock.sendall(chunk[:n])
                left -= n
        except OSError:
            pass

    t = threading.Thread(target=push, daemon=True)
    t.start()
    f = got[0]
    if isinstance(f, Exception):  # the old behaviour: it waits for the body
        try:
            f = c.recv_reply(timeout=60)
        except (socket.timeout, lc.Closed) as e:
            f = e
        rep.check(False, "%s: ERROR from the header alone, before the body" % what, "after the body: %r" % (f,))
        return c, t
    msg = f.body.get("message", "") if isinstance(f.body, dict) else ""
    rep.check(f.type == lc.ERROR and f.err_name == "TOO_LARGE" and f.rid == 5 and "--max-preauth-body" in msg
              and "attachment_length %d" % att_len in msg,
              "%s: ERROR TOO_LARGE from the header alone naming --max-preauth-body and the value" % what, msg)
    rep.check(c.expect_closed(10), "%s: then closed" % what)
    return c, t


def case_memory(rep, lpvd):
    with harness.Daemon(lpvd, tcp=True, token=True) as d:
        ep = d.tcp
        # settle start-up allocations before the baseline
        c0 = lc.Conn(ep)
        hello(c0, d.token)
        c0.close()
        time.sleep(0.5)
        d.reset_peak()
        base = hwm_kib(d)
        rss0 = d.rss_kib()
        threads = []
        conns = []
        for i in range(2):
            c, t = refused_at_header(rep, ep, BIG, "client %d declaring a 250 MiB attachment" % (i + 1))
            conns.append(c)
            threads.append(t)
        for t in threads:
            t.join(120)
        grow = (hwm_kib(d) - base) / 1024.0
        print("VmRSS %.0f MiB before; VmHWM %.0f MiB before, %.0f MiB after two 250 MiB attempts (+%.1f MiB)"
              % (rss0 / 1024.0, base / 1024.0, hwm_kib(d) / 1024.0, grow))
        rep.check(grow <= 64, "peak RSS grows by at most 64 MiB", "+%.1f MiB" % grow)
        refused_at_header(rep, ep, 1, "a 1-byte attachment")
        # the configured limits apply from the frame after a successful HELLO, even pipelined in one write
        c = lc.Conn(ep, timeout=60)
        c.send_raw(lc.encode_frame(lc.HELLO, 1, {"version": 1, "token": d.token})
                   + lc.encode_frame(lc.SCENE_LOAD, 2, {}, lc.box_scene_glb()))
        f1 = c.recv_reply(1)
        f2 = c.recv_reply(2, timeout=60)
        rep.check(f1.type == lc.HELLO | lc.REPLY and f2.type == lc.SCENE_LOAD | lc.REPLY,
                  "HELLO and a SCENE_LOAD with a glb attachment in one write: both answered", "%r, %r" % (f1, f2))
        lim = f1.body.get("limits", {})
        rep.check(lim.get("max_preauth_body") == 4096 and lim.get("max_preauth") == 16
                  and lim.get("handshake_timeout") == 10,
                  "HELLO limits carry the pre-auth defaults (4096 bytes, 16 connections, 10 s)",
                  "%r" % {k: lim.get(k) for k in ("max_preauth_body", "max_preauth", "handshake_timeout")})
        rep.check(d.alive(), "daemon alive")


def case_reply_cap(rep, lpvd):
    with harness.Daemon(lpvd, token=True) as d:
        ep = ("unix", d.unix)
        n = 20000
        c = lc.Conn(ep, timeout=30, rcvbuf=4096)
        data = b"".join(lc.encode_frame(lc.STATS, i + 1, {}) for i in range(n))
        try:
            c.send_raw(data)
        except OSError:
            pass
        got = 0
        closed = False
        t_end = time.monotonic() + 30
        while time.monotonic() < t_end:
            try:
                c.recv(timeout=max(0.1, t_end - time.monotonic()))
                got += 1
            except lc.Closed:
                closed = True
                break
            except socket.timeout:
                break
        rep.check(closed and got < n, "%d frames before HELLO, none read: dropped at the pre-auth reply cap" % n,
                  "%d replies, %s" % (got, "closed" if closed else "still open"))
        rep.check(d.alive(), "daemon alive")


def trickle(conns, stop):
    """One byte of a HELLO header every 2 s on each connection; never a whole frame."""
    hdr = lc.HEADER.pack(lc.MAGIC, lc.VERSION, lc.HELLO, 1, 0, 1000, 0)
    i = 0
    while not stop.is_set() and i < len(hdr):
        for c in conns:
            try:
                c.sock.send(hdr[i:i + 1])
            except OSError:
                pass
        i += 1
        stop.wait(2.0)


def case_slots(rep, lpvd):
    extra = [("--max-preauth", "10"), ("--handshake-timeout", "120")]
    with harness.Daemon(lpvd, tcp=True, token=True, extra=["--max-clients", "4"], optional=extra) as d:
        ep = d.tcp
        tricklers = [lc.Conn(ep, timeout=10) for _ in range(8)]
        stop = threading.Event()
        t = threading.Thread(target=trickle, args=(tricklers, stop), daemon=True)
        t.start()
        time.sleep(3)
        sessions = []
        try:
            c = lc.Conn(ep, timeout=10)
            hello(c, d.token)
            ok(c.request(lc.STATS, {}), lc.STATS)
            sessions.append(c)
            rep.check(True, "8 trickling unauthenticated connections (max-clients 4): a right HELLO gets in")
        except Exception as e:
            rep.check(False, "8 trickling unauthenticated connections (max-clients 4): a right HELLO gets in",
                      repr(e))
        # fill the pre-auth quota (8 tricklers + 2), then one more: the oldest trickler makes room
        waiting = [lc.Conn(ep, timeout=10) for _ in range(2)]
        time.sleep(0.3)
        over = lc.Conn(ep, timeout=10)
        try:
            hello(over, d.token)
            sessions.append(over)
            rep.check(True, "connection 11 while 10 wait for HELLO (--max-preauth 10) is let in and says HELLO")
        except Exception as e:
            rep.check(False, "connection 11 while 10 wait for HELLO (--max-preauth 10) is let in and says HELLO",
                      repr(e))
        try:
            f = tricklers[0].recv_reply(timeout=5)
            msg = f.body.get("message", "")
            good = f.err_name == "LIMIT" and "--max-preauth" in msg and tricklers[0].expect_closed(5)
        except (socket.timeout, lc.Closed) as e:
            good, msg = False, repr(e)
        rep.check(good, "the oldest connection waiting for HELLO got ERROR LIMIT naming --max-preauth, closed", msg)
        for w in waiting:
            w.close()
        time.sleep(0.3)
        # fill --max-clients with sessions, then one more right HELLO
        try:
            while len(sessions) < 4:
                c = lc.Conn(ep, timeout=10)
                hello(c, d.token)
                sessions.append(c)
            fifth = lc.Conn(ep, timeout=10)
            rid = fifth.send(lc.HELLO, {"version": 1, "token": d.token})
            f = fifth.recv_reply(timeout=10)
            msg = f.body.get("message", "")
            good = f.err_name == "LIMIT" and f.rid == rid and "--max-clients" in msg and fifth.expect_closed(5)
        except Exception as e:
            good, msg = False, repr(e)
        rep.check(good, "4 sessions open (--max-clients 4): a fifth right HELLO gets LIMIT naming it, closed", msg)
        try:
            ok(sessions[0].request(lc.STATS, {}), lc.STATS)
            rep.check(True, "the sessions are served meanwhile")
        except Exception as e:
            rep.check(False, "the sessions are served meanwhile", repr(e))
        stop.set()
        t.join(5)
        rep.check(d.alive(), "daemon alive")


def case_deadline(rep, lpvd):
    with harness.Daemon(lpvd, token=True, optional=[("--handshake-timeout", "2")]) as d:
        ep = ("unix", d.unix)
        silent = lc.Conn(ep, timeout=30)
        trick = lc.Conn(ep, timeout=30)
        stop = threading.Event()

        def drip():
            hdr = lc.HEADER.pack(lc.MAGIC, lc.VERSION, lc.HELLO, 1, 0, 1000, 0)
            for i in range(len(hdr)):
                if stop.wait(0.5):
                    return
                try:
                    trick.sock.send(hdr[i:i + 1])
                except OSError:
                    return

        t = threading.Thread(target=drip, daemon=True)
        t.start()
        t0 = time.monotonic()
        for name, c in (("a silent connection", silent), ("a connection trickling a header", trick)):
            try:
                f = c.recv_reply(timeout=max(0.1, 20 - (time.monotonic() - t0)))
                msg = f.body.get("message", "")
                good = f.type == lc.ERROR and f.err_name == "LIMIT" and "--handshake-timeout" in msg
                good = good and c.expect_closed(5)
            except (socket.timeout, lc.Closed) as e:
                good, msg = False, repr(e)
            dt = time.monotonic() - t0
            rep.check(good and dt < 20, "%s: ERROR LIMIT naming --handshake-timeout (2 s), closed, within 20 s"
                      % name, "%s after %.1f s" % (msg, dt))
        stop.set()
        c = lc.Conn(ep, timeout=10)
        hello(c, d.token)
        time.sleep(3)
        ok(c.request(lc.STATS, {}), lc.STATS)
        rep.check(True, "a session that said HELLO is not subject to the deadline")


def case_idle(rep, lpvd):
    with harness.Daemon(lpvd, idle_timeout=3) as d:
        c = lc.Conn(("unix", d.unix), timeout=30)
        hello(c)
        data = lc.encode_frame(lc.LIGHT_SET, 9, {"id": "x", "type": "point", "intensity": 1.0, "position": [0, 1, 0],
                                                "pad": "p" * 200})
        t0 = time.monotonic()
        f = None
        i = 0
        while time.monotonic() - t0 < 30 and i < len(data) - 1:  # never the last byte
            try:
                c.sock.send(data[i:i + 1])
            except OSError:
                break
            i += 1
            try:
                f = c.recv(timeout=0.5)
                break
            except socket.timeout:
                continue
            except lc.Closed:
                break
        dt = time.monotonic() - t0
        rep.check(f is not None and f.type == lc.BYE_REPLY and f.rid == 0 and dt < 30,
                  "a session trickling one byte every 0.5 s of a frame it never completes: BYE from the idle timer "
                  "(--idle-timeout 3) within 30 s", "%r after %.1f s, %d bytes sent" % (f, dt, i))
        rep.check(f is not None and c.expect_closed(5), "then closed")


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    ap.add_argument("--only", help="run one case: memory, reply_cap, slots, deadline, idle")
    args = ap.parse_args()
    rep = harness.Report("preauth")
    lpvd = harness.find_lpvd(args.lpvd)
    cases = [("memory", case_memory), ("reply_cap", case_reply_cap), ("slots", case_slots),
             ("deadline", case_deadline), ("idle", case_idle)]
    for name, fn in cases:
        if args.only and name != args.only:
            continue
        try:
            fn(rep, lpvd)
        except Exception as e:  # a case that breaks must not hide the others
            rep.check(False, "%s: ran to the end" % name, repr(e))
    return rep.finish()


if __name__ == "__main__":
    sys.exit(main())
