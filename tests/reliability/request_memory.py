#!/usr/bin/env python3
"""request_memory.py - the requests of all connections together hold at most --max-request-memory bytes (R7.5).

Without a daemon-wide bound each connection could hold a frame of up to --max-message bytes being read
plus up to 512 MiB of requests waiting, so 64 clients reached tens of GiB. Scaled down here:
--max-message 24 MiB, --max-request-memory 48 MiB, six authenticated clients.

1. Each client sends the header of a STATS frame declaring a 24 MiB attachment and all of it but the last
   byte. Expected: the daemon reserves at most 48 MiB (two frames; STATS "queues.request_bytes"), the
   other four wait with their frames unread, and its RSS grows by at most 48 MiB + one 64 KiB read buffer
   per client + 24 MiB of allocator slack (+ twice the budget under AddressSanitizer, whose quarantine
   keeps freed buffers resident). Before: all six were buffered (RSS +144 MiB) and STATS had no
   request_bytes.
2. Each client sends its last byte. Expected: every client gets its STATS reply (the waiting ones once
   memory frees, nothing lost), and request_bytes returns to 0.
3. The daemon refuses to start with --max-request-memory under --max-message (that frame could never be
   read).
"""

import subprocess
import sys
import threading
import time

from rel_common import harness, lc, hello

MIB = 1 << 20
MAX_MESSAGE = 24 * MIB
BUDGET = 48 * MIB
CLIENTS = 6
SLACK = 24 * MIB


def status_kib(pid, key):
    with open("/proc/%d/status" % pid) as fh:
        for line in fh:
            if line.startswith(key + ":"):
                return int(line.split()[1])
    return 0


def request_bytes(obs):
    f = obs.request(lc.STATS, {}, timeout=30)
    return f.body["queues"]["request_bytes"]


def main():
    ap = harness.common_args(__doc__.split("\n")[0])
    args = ap.parse_args()
    rep = harness.Report("request_memory")
    binary = harness.find_lpvd(args.lpvd)
    d = harness.Daemon(binary, idle_timeout=120,
                       extra=["--max-message", str(MAX_MESSAGE), "--max-request-memory", str(BUDGET),
                              "--max-clients", str(CLIENTS + 1)])
    d.start()
    try:
        ep = ("unix", d.unix)
        obs = lc.Conn(ep, timeout=30)
        hello(obs)
        rep.check(request_bytes(obs) == 0, "STATS queues.request_bytes is 0 at rest")
        conns = []
        for _ in range(CLIENTS):
            c = lc.Conn(ep, timeout=60)
            hello(c)
            conns.append(c)
        time.sleep(0.5)
        base = status_kib(d.pid, "VmRSS")
        d.reset_peak()
        att = b"\0" * (MAX_MESSAGE - 64)  # json + attachment within --max-message
        frames = [lc.encode_frame(lc.STATS, 1000 + i, {}, att) for i in range(CLIENTS)]
        errors = []
        last = threading.Event()

        def push(c, data):
            try:
                c.sock.settimeout(120)
                c.sock.sendall(data[:-1])  # a waiting client blocks here until the daemon reads on
                last.wait(120)
                c.sock.sendall(data[-1:])
            except OSError as e:
                errors.append(e)

        threads = [threading.Thread(target=push, args=(c, f), daemon=True) for c, f in zip(conns, frames)]
        for t in threads:
            t.start()
        time.sleep(3.0)  # the granted frames arrive in well under a second over a Unix socket
        held = request_bytes(obs)
        peak = max(0, status_kib(d.pid, "VmHWM") - base) * 1024
        bound = BUDGET + CLIENTS * 65536 + SLACK
        if harness.is_asan(binary):  # its quarantine keeps every freed growth step of a parser buffer resident
            bound += 2 * BUDGET
        rep.check(held <= BUDGET, "phase 1: request bytes held stay within --max-request-memory",
                  "%d MiB held, budget %d MiB" % (held // MIB, BUDGET // MIB))
        rep.check(held >= MAX_MESSAGE, "phase 1: frames that fit are reserved and read",
                  "%d MiB held" % (held // MIB))
        rep.check(peak <= bound, "phase 1: RSS grows by at most the budget + a read buffer per client + slack",
                  "peak +%.1f MiB, bound %.1f MiB" % (peak / MIB, bound / MIB))
        # phase 2: the last byte of each; the waiting frames are read as memory frees
        last.set()
        for t in threads:
            t.join(120)
        got = 0
        for i, c in enumerate(conns):
            try:
                r = c.recv_reply(1000 + i, timeout=120)
                got += r.type == (lc.STATS | lc.REPLY)
            except Exception as e:  # noqa: BLE001 - reported as a failed check
                errors.append(e)
        rep.check(got == CLIENTS and not errors, "phase 2: every client gets its STATS reply (nothing lost)",
                  "%d of %d replies, errors %r" % (got, CLIENTS, errors[:2]))
        t_end = time.monotonic() + 30
        held = request_bytes(obs)
        while held and time.monotonic() < t_end:
            time.sleep(0.2)
            held = request_bytes(obs)
        rep.check(held == 0, "phase 2: request_bytes returns to 0", "%d bytes" % held)
        # phase 3: a budget under one message is refused at start
        p = subprocess.run([binary, "serve", "--socket", d.unix + ".x", "--max-message", str(MAX_MESSAGE),
                            "--max-request-memory", str(MAX_MESSAGE - 1)], capture_output=True, text=True,
                           timeout=60)
        rep.check(p.returncode == 2 and "--max-request-memory" in p.stderr,
                  "phase 3: --max-request-memory under --max-message is refused at start",
                  "status %d, %r" % (p.returncode, p.stderr.strip()[-200:]))
        return rep.finish(d)
    finally:
        d.kill()


if __name__ == "__main__":
    sys.exit(main())
