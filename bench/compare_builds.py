#!/usr/bin/env python3
"""compare_builds.py - this build's lpvd-bench against an earlier build's, on
one machine in one run, as per-stage ratios.

Machines drift (other jobs, turbo, thermal state), so absolute times from
different days do not compare. This runs the two benches alternately, A B A
A ..., with the same arguments, and for every configuration and stage prints
the median of the per-round ratios new/old (below 1: the new build is
faster) beside both medians.

    python3 bench/compare_builds.py --baseline ../old/build/bench/lpvd-bench \\
        --new build/bench/lpvd-bench --rounds 5 -- --repeat 5 --warmup 2

An earlier build: `sh bench/build_baseline.sh REV ../old` (a worktree of REV
with this checkout's bench source, so both print the same configurations).
Rows: every stage, "total" (the stages' GPU ms) and "wall" (the whole tick
and frame on the CPU clock); a summary of the speed-ups (old / new) ends the
output. Standard library only; prints Markdown.
"""
import argparse
import re
import statistics
import subprocess
import sys

SECTION = re.compile(r"^## (.*)$")
ROW = re.compile(r"^\| (\*\*)?([a-z_]+)(\*\*)? \| (\*\*)?([0-9.]+)(\*\*)? \|$")


def parse(text):
    """{configuration: {stage: ms}} from lpvd-bench's Markdown."""
    out, current = {}, None
    for line in text.splitlines():
        m = SECTION.match(line)
        if m:
            current = out.setdefault(m.group(1).strip(), {})
            continue
        m = ROW.match(line.strip())
        if m and current is not None:
            current[m.group(2)] = float(m.group(5))
    return out


def run(binary, args):
    p = subprocess.run([binary] + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if p.returncode != 0:
        sys.exit("compare_builds: %s exited with %d:\n%s" % (binary, p.returncode, p.stderr[-2000:]))
    return parse(p.stdout), p.stdout.splitlines()[0] if p.stdout else ""


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--old", "--baseline", dest="old", required=True, help="the earlier build's lpvd-bench")
    ap.add_argument("--new", required=True, help="this build's lpvd-bench")
    ap.add_argument("--rounds", type=int, default=5, help="A/B rounds (default 5)")
    ap.add_argument("bench_args", nargs="*", help="after --: arguments for both benches")
    a = ap.parse_args()
    if a.rounds < 1:
        ap.error("--rounds must be at least 1")
    olds, news, head = [], [], ""
    for i in range(a.rounds):
        # the order swaps every round (A B, B A, ...): whichever runs second
        # in a pair has measured up to 10 % slower on the bench machine
        if i % 2 == 0:
            o, _ = run(a.old, a.bench_args)
            n, head = run(a.new, a.bench_args)
        else:
            n, head = run(a.new, a.bench_args)
            o, _ = run(a.old, a.bench_args)
        olds.append(o)
        news.append(n)
        print("compare_builds: round %d/%d done" % (i + 1, a.rounds), file=sys.stderr)
    print("# new / old, %d rounds in alternating order, medians of per-round ratios" % a.rounds)
    print()
    print("new: `%s`, old: `%s`, arguments `%s`" % (a.new, a.old, " ".join(a.bench_args)))
    print()
    print(head.lstrip("# "))
    for conf in news[0]:
        if not all(conf in o for o in olds):
            print("\n## %s\n\n(not measured by the old build)" % conf)
            continue
        print("\n## %s\n" % conf)
        print("| stage | old ms (median) | new ms (median) | new / old (median of rounds) |")
        print("|---|---:|---:|---:|")
        for stage in news[0][conf]:
            pairs = [(o[conf].get(stage), n[conf].get(stage)) for o, n in zip(olds, news)]
            pairs = [(x, y) for x, y in pairs if x is not None and y is not None]
            if not pairs:
                print("| %s | – | %.2f | new stage |" % (stage, statistics.median(n[conf][stage] for n in news)))
                continue
            ratios = [y / x for x, y in pairs if x > 0]
            print("| %s | %.2f | %.2f | %s |" % (stage, statistics.median(x for x, _ in pairs),
                                               statistics.median(y for _, y in pairs),
                                               "%.3f" % statistics.median(ratios) if ratios else "–"))
    summary(olds, news)


def summary(olds, news):
    """Speed-up (old / new, median of the rounds' ratios) of the wall and of
    each configuration's largest stages, and the propagation throughput."""
    print("\n## Summary: speed-up old / new (median of per-round ratios)\n")
    print("| configuration | wall | total | propagate |")
    print("|---|---:|---:|---:|")
    for conf in news[0]:
        if not all(conf in o for o in olds):
            continue
        cells = []
        for stage in ("wall", "total", "propagate"):
            r = [o[conf][stage] / n[conf][stage] for o, n in zip(olds, news)
                 if stage in o[conf] and stage in n[conf] and n[conf][stage] > 0]
            cells.append("%.2fx" % statistics.median(r) if r else "–")
        print("| %s | %s |" % (conf.split(":")[0] + ": " + conf.split(":")[1].split(",")[0].strip(), " | ".join(cells)))


if __name__ == "__main__":
    main()
