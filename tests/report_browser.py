#!/usr/bin/env python3
"""report_browser.py - the batch report's page (report/report_html.h) in a real
browser: Debian's chromium, headless.

Writes the job folder of tests/report_fixture.h (--fixture), runs lpvd-report
on it (--report), opens report.html with --dump-dom and checks that the page's
own script found every thumbnail loaded (body data-thumbs-loaded equal to the
number of ok items, data-thumbs-broken 0) and that the page logged nothing to
the console. Then it deletes one thumbnail and checks that the page reports it
broken, so the check can fail.

Chromium prints a page's console messages (console.log and console.error
alike, and uncaught exceptions) on stderr with --enable-logging=stderr --v=0,
one line each, as
    [PID:TID:MMDD/HHMMSS.micros:INFO:CONSOLE:LINE] "message", source: URL (LINE)
(older builds: "INFO:CONSOLE(LINE)]"). The level is not in the line, so any
console line fails the test: the page logs nothing on purpose. A probe page
with console.error checks first that such lines are still seen. A missing
image is not logged there, hence the page's own check.

Without chromium the test fails: scripts/install-deps.sh installs it.
Standard library only.
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

CONSOLE = re.compile(r":CONSOLE(?::\d+\]|\(\d+\)\])")


def fail(msg):
    print(f"report_browser: FAIL: {msg}", file=sys.stderr)
    sys.exit(1)


def chromium_dom(chromium, page, profile):
    """(dumped DOM, console lines) of page opened in headless chromium."""
    cmd = [chromium, "--headless", "--no-sandbox", "--disable-gpu", "--enable-logging=stderr", "--v=0",
           "--no-first-run", f"--user-data-dir={profile}", "--virtual-time-budget=5000", "--dump-dom",
           "file://" + os.path.abspath(page)]
    try:
        r = subprocess.run(cmd, capture_output=True, text=True, errors="replace", timeout=120)
    except subprocess.TimeoutExpired:
        fail(f"chromium did not finish on {page} within 120 s")
    if r.returncode != 0:
        fail(f"chromium exited with {r.returncode} on {page}:\n{r.stderr[-4000:]}")
    return r.stdout, [line for line in r.stderr.splitlines() if CONSOLE.search(line)]


def body_attr(dom, name):
    body = re.search(r"<body\b[^>]*>", dom)
    if not body:
        fail("no <body> in the dumped DOM")
    m = re.search(r"\s" + re.escape(name) + r'="([^"]*)"', body.group(0))
    return m.group(1) if m else None


def ok_items(job):
    """Ok items in the job's manifests, the last line of each id counting (the
    fixture's ids live in one shard each, so file order is enough here)."""
    merged = os.path.join(job, "manifest.jsonl")
    files = [merged] if os.path.exists(merged) else sorted(
        os.path.join(job, f) for f in os.listdir(job) if re.fullmatch(r"manifest-\d+-of-\d+\.jsonl", f))
    last = {}
    for path in files:
        with open(path, encoding="utf-8") as f:
            for line in f:
                try:
                    item = json.loads(line)
                except ValueError:
                    continue
                if isinstance(item, dict) and isinstance(item.get("id"), str):
                    last[item["id"]] = item
    return sum(1 for item in last.values() if item.get("status") == "ok")


def check_page(chromium, page, profile, loaded, broken):
    dom, console = chromium_dom(chromium, page, profile)
    if console:
        fail("the report logged to the console:\n" + "\n".join(console))
    if body_attr(dom, "data-thumbs-checked") != "1":
        fail("the page's script did not run to the end (no data-thumbs-checked on <body>)")
    got = (body_attr(dom, "data-thumbs-loaded"), body_attr(dom, "data-thumbs-broken"))
    if got != (str(loaded), str(broken)):
        fail(f"thumbnails loaded/broken: {got[0]}/{got[1]}, expected {loaded}/{broken}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--fixture", required=True, help="the report_fixture program")
    ap.add_argument("--report", required=True, help="the lpvd-report program")
    args = ap.parse_args()

    chromium = shutil.which("chromium")
    if not chromium:
        fail("chromium not found on PATH: this test opens the batch report in Debian's chromium "
             "(apt-get install chromium, or scripts/install-deps.sh)")

    with tempfile.TemporaryDirectory(prefix="lpvd-report-browser-") as tmp:
        profile = os.path.join(tmp, "profile")

        # The console lines are seen: a page that logs an error must show one.
        probe = os.path.join(tmp, "probe.html")
        with open(probe, "w") as f:
            f.write("<!DOCTYPE html><html><body><script>console.error('lpvd-report-probe');</script></body></html>\n")
        _, console = chromium_dom(chromium, probe, profile)
        if not any("lpvd-report-probe" in line for line in console):
            fail("chromium's console.error did not show as a CONSOLE line on stderr: its log format changed, "
                 "so this test could not see the report's errors")

        job = os.path.join(tmp, "job")
        for cmd in ([args.fixture, job], [args.report, job]):
            r = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
            if r.returncode != 0:
                fail(f"{' '.join(cmd)} exited with {r.returncode}:\n{r.stderr}")
        page = os.path.join(job, "report.html")
        with open(page, encoding="utf-8") as f:
            html = f.read()
        if re.search(r"""(?:src|href)\s*=\s*["']?(?:[a-z]+:)?//|@import|url\(""", html, re.I):
            fail("report.html refers to something outside its folder")
        ok = ok_items(job)
        if ok < 2:
            fail(f"the fixture has {ok} ok items, expected at least 2")

        check_page(chromium, page, profile, loaded=ok, broken=0)

        # The check can fail: a missing thumbnail is reported broken.
        os.remove(os.path.join(job, "thumbs", "1.png"))
        check_page(chromium, page, profile, loaded=ok - 1, broken=1)

    print(f"report_browser: ok ({ok} thumbnails loaded, none broken, no console lines; "
          "a missing one is reported broken)")


if __name__ == "__main__":
    main()
