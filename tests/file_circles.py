#!/usr/bin/env python3
"""file_circles.py - circles of files that call each other, read from a build's object files.

A file A depends on B when A's object file uses a symbol (function or
variable) that B's object defines. Strongly connected components of that
graph with more than one file are circles: none of their files can be
understood or changed alone. Usage:

  python3 file_circles.py BUILD_DIR SOURCE_DIR [SOURCE_DIR...]

e.g. `file_circles.py build gpu server`: the circles among the files of gpu/
and server/ (each directory's files with the files of its subdirectories).
Exit status 1 when there is a circle, 0 when none.
"""
import os
import subprocess
import sys


def source_root(build):
    """The source tree the build was configured from (CMakeCache.txt), or None."""
    try:
        with open(os.path.join(build, 'CMakeCache.txt'), encoding='utf-8') as f:
            for line in f:
                if line.startswith('CMAKE_HOME_DIRECTORY:'):
                    return line.split('=', 1)[1].strip()
    except OSError:
        pass
    return None


def objects(build, dirs):
    """{source path relative to the repo: object path} for the sources under dirs
    (an object whose source is gone, left by an earlier build, is not read)."""
    top = source_root(build)
    out = {}
    for folder, _, files in os.walk(build):
        for f in files:
            if not (f.endswith('.c.o') or f.endswith('.cpp.o')):
                continue
            path = os.path.join(folder, f)
            # CMake: build/<dir>/CMakeFiles/<target>.dir/<source relative to dir>.o
            rel = os.path.relpath(path, build)
            parts = rel.split(os.sep)
            if 'CMakeFiles' not in parts:
                continue
            i = parts.index('CMakeFiles')
            # a source outside the target's folder is spelled with '__' for '..'
            src = os.path.normpath(os.path.join(*(parts[:i] + ['..' if p == '__' else p for p in parts[i + 2:]])))[:-2]
            if top and not os.path.exists(os.path.join(top, src)):
                continue
            if any(src == d or src.startswith(d.rstrip('/') + '/') for d in dirs):
                out.setdefault(src, path)
    return out


def symbols(objs):
    """{object: (defined, used)} for every object, from one `nm -A` run (one
    process for all: the test runs on every CI build)."""
    out = {o: (set(), set()) for o in objs}
    text = subprocess.run(['nm', '-A'] + list(objs), capture_output=True, text=True, check=True).stdout
    for line in text.splitlines():
        head, sep, rest = line.partition('.o:')  # "OBJECT.o:ADDRESS TYPE NAME" or "OBJECT.o:  U NAME"
        name = head + '.o'
        if not sep or name not in out:
            continue
        p = rest.split()
        if len(p) == 2 and p[0] == 'U':
            out[name][1].add(p[1])
        elif len(p) == 3 and p[1] in 'TDBRGSC':
            out[name][0].add(p[2])
    return out


def sccs(graph):
    index, low, stack, on, out, n = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = n[0]
        n[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def main():
    if len(sys.argv) < 3:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    build, dirs = sys.argv[1], [d.rstrip('/') for d in sys.argv[2:]]
    objs = objects(build, dirs)
    if not objs:
        print('file_circles: no object files for %s under %s (build first)' % (', '.join(dirs), build),
              file=sys.stderr)
        return 2
    owner, uses = {}, {}
    syms = symbols(objs.values())
    for src, obj in objs.items():
        d, u = syms[obj]
        uses[src] = u
        for s in d:
            owner[s] = src
    graph = {src: {owner[s] for s in uses[src] if s in owner and owner[s] != src} for src in objs}
    circles = [c for c in sccs(graph) if len(c) > 1]
    print('file_circles: %d files in %s, %d circle(s)' % (len(objs), ', '.join(dirs), len(circles)))
    for c in circles:
        print('  circle of %d: %s' % (len(c), ' '.join(c)))
        for a in c:
            calls = sorted(b for b in graph[a] if b in c)
            print('    %s -> %s' % (a, ', '.join(calls)))
    return 1 if circles else 0


if __name__ == '__main__':
    sys.exit(main())
