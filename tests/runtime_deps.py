#!/usr/bin/env python3
"""runtime_deps.py - the runtime packages are enough to run what was built (issue 33, item 6).

docker/Dockerfile's image installs only `scripts/install-deps.sh --runtime` and copies lpvd and
lpvctl in. This checks, on the build machine, that every shared library the two binaries load
(`ldd`) belongs to a package of that list or of what the list depends on (`apt-cache depends
--recurse`, the packages apt would install with it), and that the libraries lpvd opens itself at
run time (Mesa's EGL vendor, its DRI drivers, OSMesa) come from listed packages.

    python3 tests/runtime_deps.py --lpvd build/server/lpvd --lpvctl build/clients/lpvctl/lpvctl
"""

import argparse
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# The sanitizers' own runtimes: the test suite's second build links them (scripts/test.sh), the
# image's build never does.
SANITIZER_RUNTIMES = re.compile(r"/lib(asan|ubsan|lsan|tsan)\.so")

# What lpvd dlopens (gpu/context.c): a file of each, and so its package, must be installed.
OPENED = ["libEGL_mesa.so.0", "swrast_dri.so", "libOSMesa.so.8"]


def run(*cmd):
    return subprocess.run(cmd, check=True, capture_output=True, text=True).stdout


def packages_of(paths):
    """{path: the Debian package that owns it (dpkg -S, one call), or None}, by real path or as given."""
    paths = sorted(set(paths))
    asked = sorted(set(paths) | {os.path.realpath(p) for p in paths})
    r = subprocess.run(["dpkg", "-S", *asked], capture_output=True, text=True)
    owner = {}
    for line in r.stdout.splitlines():
        pkg, _, path = line.partition(": ")
        owner[path.strip()] = pkg.split(",")[0].split(":")[0].strip()
    return {p: owner.get(os.path.realpath(p)) or owner.get(p) for p in paths}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--lpvd", required=True)
    ap.add_argument("--lpvctl", required=True)
    a = ap.parse_args()
    runtime = run("sh", os.path.join(ROOT, "scripts", "install-deps.sh"), "--print", "runtime").split()
    closure = set(runtime)
    out = run("apt-cache", "depends", "--recurse", "--no-recommends", "--no-suggests", "--no-conflicts",
              "--no-breaks", "--no-replaces", "--no-enhances", *runtime)
    for line in out.splitlines():
        if line and not line[0].isspace():
            closure.add(line.strip().strip("<>").split(":")[0])
    failures = []
    loaded = {}  # path -> the binary that loads it
    for binary in (a.lpvd, a.lpvctl):
        for line in run("ldd", binary).splitlines():
            m = re.search(r"=>\s+(/\S+)", line) or re.match(r"\s*(/\S+)", line)
            if m and not SANITIZER_RUNTIMES.search(m.group(1)):
                loaded.setdefault(m.group(1), binary)
    opened = {}
    for name in OPENED:
        found = run("sh", "-c", "find /usr/lib -name '%s' 2>/dev/null | head -1" % name).strip()
        if found:
            opened[name] = found
    owner = packages_of(list(loaded) + list(opened.values()))
    for path, binary in sorted(loaded.items()):
        pkg = owner[path]
        if pkg is None:
            failures.append("%s: %s belongs to no package" % (binary, path))
        elif pkg not in closure:
            failures.append("%s: %s comes from %s, which the runtime packages (%s) do not bring"
                            % (binary, path, pkg, " ".join(runtime)))
    for name in OPENED:
        pkg = owner.get(opened.get(name, ""))
        if pkg is None or pkg not in runtime:
            failures.append("%s (opened by lpvd at run time) comes from %s, not a listed runtime package"
                            % (name, pkg or "no installed package"))
    for f in failures:
        print("runtime_deps: " + f)
    print("runtime_deps: %d runtime packages (%d with what they depend on); %s" %
          (len(runtime), len(closure), "FAILED" if failures else "every library is covered"))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
