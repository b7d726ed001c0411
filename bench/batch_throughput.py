#!/usr/bin/env python3
"""batch_throughput.py - images per hour: one `lpvd batch` process against one
`lpvd render` process per image, on the same items (issue 15, item 7;
docs/batch.md).

The job: the built-in Cornell box and the repository's scenes (courtyard,
blinds, glossy, emissive-room) x presets fast and balanced x the file's camera
at 10 fields of view (30..75 degrees) = 100 items at --size. Each item maps
one-to-one to an `lpvd render SCENE --preset P --fov F --size WxH` command, so
both sides render the same images; the script checks that they are
byte-identical PNGs, then prints images per hour for each and their ratio.

usage: python3 bench/batch_throughput.py --lpvd build/server/lpvd [--size 320x240] [--fovs 10] [--out DIR]
"""
import argparse
import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

SCENES = [None, "courtyard.glb", "blinds.glb", "glossy.glb", "emissive-room.glb"]
PRESETS = ["fast", "balanced"]


def digest(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--lpvd", required=True)
    ap.add_argument("--size", default="320x240")
    ap.add_argument("--fovs", type=int, default=10)
    ap.add_argument("--out", default=None, help="keep the outputs here (default: a temporary folder)")
    a = ap.parse_args()
    lpvd = os.path.abspath(a.lpvd)
    src = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenes")
    work = a.out or tempfile.mkdtemp(prefix="lpvd-batch-bench-")
    os.makedirs(work, exist_ok=True)
    for s in SCENES:
        if s:
            shutil.copy(os.path.join(src, s), work)
    w, h = (int(v) for v in a.size.split("x"))
    fovs = [30 + 45 * i / max(1, a.fovs - 1) for i in range(a.fovs)]
    job = {
        "lpvd_batch": 1,
        "size": [w, h],
        "scenes": [{"name": "cornell"} if s is None else {"path": s} for s in SCENES],
        "cameras": [{"name": "fov%02d" % i, "camera": 0, "fov_deg": f} for i, f in enumerate(fovs)],
        "settings": [{"name": p, "preset": p} for p in PRESETS],
        "outputs": ["png"],
    }
    jp = os.path.join(work, "job.json")
    with open(jp, "w") as f:
        json.dump(job, f)
    out_batch = os.path.join(work, "batch")
    shutil.rmtree(out_batch, ignore_errors=True)
    t0 = time.monotonic()
    p = subprocess.run([lpvd, "batch", jp, "--out", out_batch, "--progress", "off"], capture_output=True, text=True)
    t_batch = time.monotonic() - t0
    if p.returncode != 0:
        sys.exit("lpvd batch failed:\n" + p.stderr[-3000:])
    entries = [json.loads(line) for line in open(os.path.join(out_batch, "manifest-0-of-1.jsonl"))]
    out_render = os.path.join(work, "render")
    os.makedirs(out_render, exist_ok=True)
    t0 = time.monotonic()
    same = 0
    for e in entries:
        s = e["scene"]
        cam = next(c for c in job["cameras"] if c["name"] == e["camera"])
        png = os.path.join(out_render, "%d.png" % e["index"])
        cmd = [lpvd, "render"] + ([] if s.startswith("built-in") else [os.path.join(work, s)]) + [
            "-o", png, "--preset", e["settings_name"], "--camera", "0", "--fov", repr(cam["fov_deg"]),
            "--size", "%dx%d" % (w, h)]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit("lpvd render failed: %s\n%s" % (" ".join(cmd), r.stderr[-2000:]))
    t_render = time.monotonic() - t0
    for e in entries:
        same += digest(os.path.join(out_render, "%d.png" % e["index"])) == digest(
            os.path.join(out_batch, e["outputs"][0]["path"]))
    n = len(entries)
    print("items: %d (%d scenes x %d presets x %d cameras) at %dx%d" % (n, len(SCENES), len(PRESETS), len(fovs), w, h))
    print("lpvd batch, one process:      %7.1f s  %7.0f images/hour" % (t_batch, 3600.0 * n / t_batch))
    print("lpvd render, a process each:  %7.1f s  %7.0f images/hour" % (t_render, 3600.0 * n / t_render))
    print("batch / render throughput:    %7.2fx" % (t_render / t_batch))
    print("identical PNGs:               %d of %d" % (same, n))
    if not a.out:
        shutil.rmtree(work, ignore_errors=True)
    return 0 if same == n else 1


if __name__ == "__main__":
    sys.exit(main())
