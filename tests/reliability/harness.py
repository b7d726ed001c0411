#!/usr/bin/env python3
"""harness.py - starts and stops an `lpvd serve` daemon for the serve tests and benchmarks.

As a library:

    from harness import Daemon, find_lpvd
    with Daemon(find_lpvd(args.lpvd), tcp=True, token=True, scene_root=True) as d:
        d.unix      # socket path          d.tcp    ("tcp", "127.0.0.1", port) or None
        d.token     # token or None        d.pid, d.rss_kib(), d.fd_count(), d.alive()
        rc = d.stop()   # SIGTERM, wait; returns the exit status (negative: killed by that signal)

The daemon gets a fresh temporary directory (socket, token file, scene root,
its log); everything is removed and the daemon is killed at exit, also when
the test fails or is interrupted (atexit + SIGTERM/SIGINT/SIGHUP handlers).
Flags the daemon's `serve --help` does not mention are dropped with a warning
(so a daemon lacking a feature still starts and the cases for it fail, rather
than nothing running at all).

As a command (what ctest runs):

    harness.py --lpvd BIN [--tcp] [--token] [--scene-root] [--idle-timeout S] [--daemon-arg=ARG ...] -- CMD ...

starts the daemon, runs CMD with {unix} {tcp} {token} {scene_root} {pid}
replaced, stops the daemon and exits with CMD's status (or 1 if the daemon
died during CMD or did not start).
"""

import argparse
import atexit
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "clients", "conformance"))

_LIVE = []


def _cleanup_all():
    for d in list(_LIVE):
        d.kill()


def _on_signal(signum, frame):
    _cleanup_all()
    signal.signal(signum, signal.SIG_DFL)
    os.kill(os.getpid(), signum)


atexit.register(_cleanup_all)
for _s in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP):
    try:
        signal.signal(_s, _on_signal)
    except (ValueError, OSError):
        pass


def find_lpvd(given=None):
    """The lpvd binary: given, $LPVD_BIN, or the first build folder that has one."""
    for cand in [given, os.environ.get("LPVD_BIN")] + [os.path.join(ROOT, b, "server", "lpvd") for b in
                                                      ("build-t", "build", "build-asan")]:
        if cand and os.path.isfile(cand) and os.access(cand, os.X_OK):
            return os.path.abspath(cand)
    raise SystemExit("harness: no lpvd binary (give --lpvd or set LPVD_BIN)")


def free_port():
    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def is_asan(binary):
    """True when the binary was built with AddressSanitizer (RSS/fd bounds are relaxed then)."""
    try:
        with open(binary, "rb") as fh:
            return b"__asan_init" in fh.read()
    except OSError:
        return False


class DaemonError(Exception):
    pass


class Daemon:
    def __init__(self, binary, tcp=False, token=False, scene_root=False, idle_timeout=None, extra=(),
                 optional=(), env=None, quiet=False, start_timeout=60.0):
        self.binary = binary
        self.want_tcp = tcp
        self.want_token = token
        self.want_root = scene_root
        self.idle_timeout = idle_timeout
        self.extra = list(extra)
        self.optional = list(optional)  # (flag, value) pairs, dropped when --help does not mention them
        self.env = dict(os.environ if env is None else env)
        self.quiet = quiet
        self.start_timeout = start_timeout
        self.proc = None
        self.dir = None
        self.unix = None
        self.tcp = None
        self.token = None
        self.scene_root = None
        self.log_path = None
        self.dropped = []
        self.asan = is_asan(binary)
        self.stopped_rc = None

    # -- set-up
    def _help_text(self):
        try:
            p = subprocess.run([self.binary, "serve", "--help"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                               timeout=20, env=self.env)
            return p.stdout.decode(errors="replace")
        except (OSError, subprocess.TimeoutExpired):
            return ""

    def _args(self):
        helptext = self._help_text()
        args = [self.binary, "serve", "--socket", self.unix]
        opt = []
        if self.want_tcp:
            opt.append(("--listen", "127.0.0.1:%d" % self.tcp[2]))
        if self.want_token:
            opt.append(("--token-file", self.token_file))
        if self.want_root:
            opt.append(("--scene-root", self.scene_root))
        if self.idle_timeout:
            opt.append(("--idle-timeout", "%g" % self.idle_timeout))
        opt += self.optional
        for flag, val in opt:
            if helptext and flag not in helptext:
                self.dropped.append(flag)
                continue
            args += [flag, val]
        return args + self.extra

    def start(self):
        self.dir = tempfile.mkdtemp(prefix="lpvd-test-")
        os.chmod(self.dir, 0o700)
        self.unix = os.path.join(self.dir, "lpvd.sock")
        self.log_path = os.path.join(self.dir, "daemon.log")
        if self.want_tcp:
            self.tcp = ("tcp", "127.0.0.1", free_port())
        if self.want_token:
            self.token = "tok-%s" % os.urandom(12).hex()
            self.token_file = os.path.join(self.dir, "token")
            with open(self.token_file, "w") as fh:
                fh.write(self.token + "\n")
            os.chmod(self.token_file, 0o600)
        if self.want_root:
            self.scene_root = os.path.join(self.dir, "scenes")
            os.mkdir(self.scene_root)
        if self.asan:
            # keep ASan's quarantine small so RSS measurements mean something
            o = self.env.get("ASAN_OPTIONS", "")
            if "quarantine_size_mb" not in o:
                self.env["ASAN_OPTIONS"] = (o + ":" if o else "") + "quarantine_size_mb=16"
        args = self._args()
        if self.dropped and not self.quiet:
            print("harness: warning: `lpvd serve --help` does not mention %s; started without (the cases "
                  "needing them will fail)" % ", ".join(self.dropped), file=sys.stderr)
        self.log = open(self.log_path, "wb")
        self.proc = subprocess.Popen(args, stdout=self.log, stderr=subprocess.STDOUT, env=self.env,
                                     start_new_session=True)
        _LIVE.append(self)
        deadline = time.monotonic() + self.start_timeout
        while True:
            if self.proc.poll() is not None:
                raise DaemonError("lpvd serve exited with %d during start-up: %s\n%s"
                                  % (self.proc.returncode, " ".join(args), self.log_tail()))
            if os.path.exists(self.unix):
                try:
                    s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
                    s.settimeout(2)
                    s.connect(self.unix)
                    s.close()
                    break
                except OSError:
                    s.close()
            if time.monotonic() > deadline:
                self.kill()
                raise DaemonError("lpvd serve did not listen on %s within %g s:\n%s"
                                  % (self.unix, self.start_timeout, self.log_tail()))
            time.sleep(0.05)
        if self.tcp and "--listen" not in self.dropped:
            # the TCP listener comes up with the Unix one; give it a moment
            t_end = time.monotonic() + 5
            while time.monotonic() < t_end:
                try:
                    socket.create_connection(self.tcp[1:], timeout=1).close()
                    break
                except OSError:
                    time.sleep(0.05)
        if not self.quiet:
            print("harness: lpvd serve pid %d on %s%s%s" % (self.proc.pid, self.unix,
                                                           (" and %s:%d" % self.tcp[1:]) if self.tcp and "--listen" not in self.dropped
                                                           else "",
                                                           " (ASan build)" if self.asan else ""), file=sys.stderr)
        return self

    # -- inspection
    @property
    def pid(self):
        return self.proc.pid

    def alive(self):
        return self.proc is not None and self.proc.poll() is None

    def rss_kib(self):
        with open("/proc/%d/status" % self.pid) as fh:
            for line in fh:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
        return 0

    def reset_peak(self):
        """Sets VmHWM back to the RSS now (proc(5): clear_refs "5"), so a peak read later is that of what
        follows: the start's self-test (serve_gl.c) leaves VmHWM well above the RSS at rest, which
        would hide any growth smaller than that."""
        with open("/proc/%d/clear_refs" % self.pid, "w") as fh:
            fh.write("5")

    def fd_count(self):
        return len(os.listdir("/proc/%d/fd" % self.pid))

    def log_tail(self, n=4000):
        try:
            with open(self.log_path, "rb") as fh:
                data = fh.read()
            return data[-n:].decode(errors="replace")
        except (OSError, TypeError):
            return ""

    # -- tear-down
    def stop(self, timeout=20.0):
        """SIGTERM and wait; SIGKILL after timeout. Returns the exit status (negative = signal)."""
        if self.proc is None:
            return None
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(timeout)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
                self.stopped_rc = "killed after %g s" % timeout
        rc = self.proc.returncode
        self._cleanup_files()
        return rc

    def kill(self):
        if self.proc is not None and self.proc.poll() is None:
            try:
                os.killpg(self.proc.pid, signal.SIGKILL)
            except OSError:
                pass
            try:
                self.proc.wait(5)
            except subprocess.TimeoutExpired:
                pass
        self._cleanup_files()

    def _cleanup_files(self):
        if self in _LIVE:
            _LIVE.remove(self)
        try:
            self.log.close()
        except Exception:
            pass
        if self.dir and os.environ.get("LPVD_KEEP_TEST_DIR") != "1":
            # keep the log visible on failure by copying it out first
            shutil.rmtree(self.dir, ignore_errors=True)
            self.dir = None

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        if self.alive():
            self.stop()
        else:
            self.kill()


class Report:
    """PASS/FAIL lines for the reliability scripts and the closing 'N passed, M failed'."""

    def __init__(self, name):
        self.name = name
        self.passed = 0
        self.failed = 0

    def check(self, cond, what, detail=""):
        if cond:
            self.passed += 1
            print("PASS %s: %s%s" % (self.name, what, (" -- " + detail) if detail else ""), flush=True)
        else:
            self.failed += 1
            print("FAIL %s: %s%s" % (self.name, what, (" -- " + detail) if detail else ""), flush=True)
        return cond

    def finish(self, daemon=None):
        if self.failed and daemon is not None:
            tail = daemon.log_tail(2000)
            if tail:
                print("--- daemon log (tail) ---\n%s\n---" % tail)
        print("%d passed, %d failed" % (self.passed, self.failed))
        return 1 if self.failed else 0


def common_args(description):
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("--lpvd", help="the lpvd binary (default: $LPVD_BIN or build-t/server/lpvd)")
    return ap


def main(argv=None):
    argv = list(sys.argv[1:] if argv is None else argv)
    if "--" not in argv:
        raise SystemExit("usage: harness.py [options] -- CMD ...")
    i = argv.index("--")
    ap = argparse.ArgumentParser(description="run a command against a fresh lpvd serve daemon")
    ap.add_argument("--lpvd")
    ap.add_argument("--tcp", action="store_true")
    ap.add_argument("--token", action="store_true")
    ap.add_argument("--scene-root", action="store_true")
    ap.add_argument("--idle-timeout", type=float)
    ap.add_argument("--daemon-arg", action="append", default=[])
    opts = ap.parse_args(argv[:i])
    cmd = argv[i + 1:]
    d = Daemon(find_lpvd(opts.lpvd), tcp=opts.tcp, token=opts.token, scene_root=opts.scene_root,
               idle_timeout=opts.idle_timeout, extra=opts.daemon_arg)
    try:
        d.start()
    except DaemonError as e:
        print("harness: %s" % e)
        return 1
    subst = {"unix": d.unix, "tcp": ("%s:%d" % d.tcp[1:]) if d.tcp else "", "token": d.token or "",
             "scene_root": d.scene_root or "", "pid": str(d.pid)}
    cmd = [a.format(**subst) if "{" in a else a for a in cmd]
    try:
        rc = subprocess.call(cmd)
    finally:
        died = not d.alive()
        drc = d.proc.returncode if died else None
        tail = d.log_tail()
        src = d.stop()
    if died:
        print("harness: FAIL the daemon died during the run (status %r)\n%s" % (drc, tail))
        return 1
    if src != 0:
        print("harness: note: the daemon exited with status %r on SIGTERM (R7.4 wants 0)" % src)
    if rc != 0:
        # a failed case is often explained by what the daemon said (why it
        # closed a connection, what it refused): keep it in the test's log
        print("harness: the command failed (status %r); the daemon's log ends:\n%s" % (rc, tail))
    return rc


if __name__ == "__main__":
    sys.exit(main())
