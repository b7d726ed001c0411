#!/usr/bin/env python3
"""batch_cli.py - `lpvd batch` from the outside (docs/batch.md), one case per run:

  shards   N shards as N concurrent processes render exactly the job's items,
           each once, byte-identical to a single-process run; the Indexed
           Job's environment (JOB_COMPLETION_INDEX, LPVD_SHARDS) picks the
           same shard as --shard; --merge combines the manifests
  resume   SIGTERM after the first item: the item in flight finishes, no
           temporary file is left, exit 3; the re-run renders only the rest
           (no item twice) and a third run renders nothing
  failures a missing scene and a torn manifest line: the bad item is recorded
           with an error naming the file, the others are rendered, exit 1
  errors   bad job files are refused with exit 2 and a message naming the key
  features animation times (the frame at t equals the file posed there),
           light overrides, irradiance at points, ambient occlusion
  links    symbolic links inside --out are never written through (issue 31,
           item 7): a linked item folder fails that item, naming the link; a
           link in place of an output, a manifest, contact.png is replaced, or
           refused, never its target written; a linked thumbs/ is refused;
           and a FIFO as the points file is refused at once (item 9)
  schema   the example job (scenes/batch-example.json) is valid against
           docs/batch.schema.json and `lpvd batch --list` expands it; job files
           the schema refuses, lpvd refuses too

usage: batch_cli.py --lpvd PATH --source DIR CASE
"""
import argparse
import hashlib
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

FAILS = []


def check(cond, what):
    if not cond:
        FAILS.append(what)
        print("FAIL:", what)
    return cond


def run(lpvd, *args, env=None, timeout=600):
    p = subprocess.run([lpvd, "batch", *args], capture_output=True, text=True, env=env, timeout=timeout)
    return p.returncode, p.stdout, p.stderr


def manifest_lines(out):
    lines = []
    for name in sorted(os.listdir(out)):
        if name.startswith("manifest-") and name.endswith(".jsonl"):
            with open(os.path.join(out, name)) as f:
                lines += [json.loads(line) for line in f if line.strip()]
    return lines


def digests(out):
    """Every output file under out (not manifests, not the report) -> sha256."""
    d = {}
    for root, _, files in os.walk(out):
        for f in files:
            if f.startswith("manifest") or f in ("report.html", "contact.png") or "/thumbs" in root:
                continue
            p = os.path.join(root, f)
            with open(p, "rb") as fh:
                d[os.path.relpath(p, out)] = hashlib.sha256(fh.read()).hexdigest()
    return d


def small_job(tmp, source, extra_scene=None):
    """A 12-item job over the built-in box and the courtyard at 48x48."""
    shutil.copy(os.path.join(source, "scenes", "courtyard.glb"), tmp)
    scenes = [{"name": "cornell"}, {"path": "courtyard.glb"}]
    if extra_scene:
        scenes.append(extra_scene)
    job = {
        "lpvd_batch": 1,
        "size": [48, 48],
        "scenes": scenes,
        "cameras": [{"name": "file"}, {"name": "orbit", "orbit": {"views": 2, "elevation_deg": 20}}],
        "settings": [{"name": "fast", "preset": "fast"}, {"name": "iv", "technique": "iv", "iv_rays": 32}],
        "outputs": ["png", "exr"],
    }
    path = os.path.join(tmp, "job.json")
    with open(path, "w") as f:
        json.dump(job, f)
    return path


def listed(lpvd, job, *extra):
    rc, out, err = run(lpvd, job, "--list", *extra)
    check(rc == 0, "--list exits 0: " + err)
    return [line.split("\t") for line in out.splitlines()]


def case_shards(lpvd, source, tmp):
    job = small_job(tmp, source)
    items = listed(lpvd, job)
    ids = [i[1] for i in items]
    check(len(ids) == 12 and len(set(ids)) == 12, "the job expands to 12 distinct items: %r" % ids)
    one = os.path.join(tmp, "one")
    rc, _, err = run(lpvd, job, "--out", one, "--progress", "lines")
    check(rc == 0, "single run exits 0: " + err[-2000:])
    n = 3
    sharded = os.path.join(tmp, "sharded")
    procs = [subprocess.Popen([lpvd, "batch", job, "--out", sharded, "--shard", "%d/%d" % (i, n), "--progress", "off"],
                              stderr=subprocess.PIPE, text=True) for i in range(n)]
    for i, p in enumerate(procs):
        _, err = p.communicate(timeout=600)
        check(p.returncode == 0, "shard %d/%d exits 0: %s" % (i, n, err[-2000:]))
    lines = manifest_lines(sharded)
    got = [e["id"] for e in lines]
    check(sorted(got) == sorted(ids), "the shards rendered exactly the job's items, each once")
    per_shard = [len([e for e in lines if e["shard"] == [i, n]]) for i in range(n)]
    check(all(c > 0 for c in per_shard), "every shard got work: %r" % per_shard)
    a, b = digests(one), digests(sharded)
    check(len(a) == 24, "two outputs per item in the single run: %d" % len(a))
    check(a == b, "sharded outputs byte-identical to the single run: differ in %r" %
          sorted(k for k in set(a) | set(b) if a.get(k) != b.get(k))[:5])
    # the listed shard of every item is the shard that rendered it
    shard_of = {i[1]: i[2] for i in listed(lpvd, job, "--shard", "0/3")}
    for i in range(1, n):
        shard_of.update({x[1]: x[2] for x in listed(lpvd, job, "--shard", "%d/%d" % (i, n))})
    check(all(shard_of[e["id"]] == "%d/%d" % tuple(e["shard"]) for e in lines), "--list names each item's shard")
    # Kubernetes Indexed Job environment = --shard
    env = dict(os.environ, JOB_COMPLETION_INDEX="1", LPVD_SHARDS="3")
    rc, out, err = run(lpvd, job, "--list", env=env)
    check(rc == 0 and out == subprocess.run([lpvd, "batch", job, "--list", "--shard", "1/3"], capture_output=True,
                                            text=True).stdout, "JOB_COMPLETION_INDEX=1 LPVD_SHARDS=3 lists shard 1/3")
    env = dict(os.environ, JOB_COMPLETION_INDEX="1")
    rc, _, err = run(lpvd, job, "--out", os.path.join(tmp, "x"), env=env)
    check(rc == 2 and "LPVD_SHARDS" in err, "JOB_COMPLETION_INDEX without LPVD_SHARDS is refused: " + err)
    # an item's image does not depend on the item before it: a camera that
    # moves less than a cell would get the daemon's cached volume
    for name, cams in (("pair", [40, 50]), ("alone", [50])):
        j = {"lpvd_batch": 1, "size": [48, 48], "scenes": [{"path": "courtyard.glb"}],
             "cameras": [{"name": "fov%d" % f, "camera": 0, "fov_deg": f} for f in cams],
             "settings": [{"name": "fast", "preset": "fast"}], "outputs": ["exr"]}
        with open(os.path.join(tmp, name + ".json"), "w") as f:
            json.dump(j, f)
        rc, _, err = run(lpvd, os.path.join(tmp, name + ".json"), "--out", os.path.join(tmp, name), "--progress", "off")
        check(rc == 0, name + " runs: " + err[-500:])
    check(digests(os.path.join(tmp, "pair")).get("courtyard/fov50/file/fast.exr") ==
          digests(os.path.join(tmp, "alone")).get("courtyard/fov50/file/fast.exr") is not None,
          "the fov 50 image is the same after the fov 40 one as alone")
    rc, _, err = run(lpvd, job, "--out", sharded, "--merge")
    with open(os.path.join(sharded, "manifest.jsonl")) as f:
        merged = [json.loads(line) for line in f]
    check(rc == 0 and [e["id"] for e in merged] == ids, "--merge writes every item once, in the job's order")
    rc, _, err = run(lpvd, job, "--out", sharded, "--progress", "lines")
    check(rc == 0 and "12 already done" in err, "a run after the shards renders nothing: " + err[-500:])


def case_resume(lpvd, source, tmp):
    job = small_job(tmp, source)
    out = os.path.join(tmp, "out")
    p = subprocess.Popen([lpvd, "batch", job, "--out", out, "--progress", "lines"], stderr=subprocess.PIPE,
                         text=True)
    deadline = time.time() + 300
    man = os.path.join(out, "manifest-0-of-1.jsonl")
    while time.time() < deadline:  # wait for the first item's manifest line
        if os.path.exists(man) and open(man).read().count("\n") >= 1:
            break
        time.sleep(0.02)
    p.send_signal(signal.SIGTERM)
    _, err = p.communicate(timeout=300)
    first = manifest_lines(out)
    check(p.returncode == 3, "SIGTERM mid-job exits 3 (resumable): %d %s" % (p.returncode, err[-1000:]))
    check(0 < len(first) < 12, "stopped after the item in flight: %d of 12 done" % len(first))
    check("run again to resume" in err, "says how to resume: " + err[-500:])
    tmps = [f for _, _, fs in os.walk(out) for f in fs if ".tmp-" in f]
    check(not tmps, "no temporary file left behind: %r" % tmps)
    check(all(e["status"] == "ok" and e["outputs"] for e in first), "every recorded item is complete")
    for e in first:
        for o in e["outputs"]:
            check(os.path.getsize(os.path.join(out, o["path"])) > 0, "output written: " + o["path"])
    rc, _, err = run(lpvd, job, "--out", out, "--progress", "lines")
    check(rc == 0, "the re-run completes the job: " + err[-1000:])
    ids = [e["id"] for e in manifest_lines(out)]
    check(len(ids) == 12 and len(set(ids)) == 12, "over both runs every item rendered once: %d lines, %d ids" %
          (len(ids), len(set(ids))))
    rc, _, err = run(lpvd, job, "--out", out, "--progress", "lines")
    check(rc == 0 and "0 done" in err and "12 already done" in err, "a third run renders nothing: " + err[-500:])
    # SIGKILL in the middle of an item: nothing to finish it; the re-run
    # renders what has no ok line (the killed item included) and removes
    # what the killed process was writing
    out2 = os.path.join(tmp, "killed")
    p = subprocess.Popen([lpvd, "batch", job, "--out", out2, "--progress", "off"], stderr=subprocess.DEVNULL)
    man2 = os.path.join(out2, "manifest-0-of-1.jsonl")
    deadline = time.time() + 300
    while time.time() < deadline and not (os.path.exists(man2) and open(man2).read().count("\n") >= 2):
        time.sleep(0.005)
    p.kill()
    p.wait()
    before = len(manifest_lines(out2))
    # what a process killed while writing leaves: a temporary of an item not yet done
    pending = [i[1] for i in listed(lpvd, job) if i[1] not in {e["id"] for e in manifest_lines(out2)}]
    check(len(pending) > 0, "items were left by the kill")
    leftover = os.path.join(out2, pending[-1] + ".tmp-999999.png")
    os.makedirs(os.path.dirname(leftover), exist_ok=True)
    with open(leftover, "wb") as f:
        f.write(b"half a PNG")
    rc, _, err = run(lpvd, job, "--out", out2, "--progress", "lines")
    lines = manifest_lines(out2)
    ids = [e["id"] for e in lines if e["status"] == "ok"]
    check(rc == 0 and 0 < before < 12 and len(ids) == 12 and len(set(ids)) == 12,
          "after SIGKILL (%d done) the re-run completes the job, every item once: rc %d, %d ok lines" %
          (before, rc, len(ids)))
    tmps = [f for _, _, fs in os.walk(out2) for f in fs if ".tmp-" in f]
    check(not tmps, "the killed process's temporary files are gone: %r" % tmps)
    # an output deleted after the fact is rendered again
    victim = manifest_lines(out)[0]["outputs"][0]["path"]
    os.remove(os.path.join(out, victim))
    rc, _, err = run(lpvd, job, "--out", out, "--progress", "lines")
    check(rc == 0 and "1 done" in err and os.path.exists(os.path.join(out, victim)),
          "an item whose output vanished is rendered again: " + err[-500:])


def case_failures(lpvd, source, tmp):
    job = small_job(tmp, source, extra_scene={"name": "ghost", "path": "missing.glb"})
    out = os.path.join(tmp, "out")
    os.makedirs(out)
    with open(os.path.join(out, "manifest-0-of-1.jsonl"), "w") as f:
        f.write('{"id": "cornell/file/file/fast", "status": "ok", "outp')  # torn by a crash
    rc, _, err = run(lpvd, job, "--out", out, "--progress", "lines")
    lines = manifest_lines_tolerant(out)
    bad = [e for e in lines if e["status"] == "failed"]
    good = [e for e in lines if e["status"] == "ok"]
    check(rc == 1, "exit 1 when an item failed: %d" % rc)
    check("unreadable manifest line" in err, "the torn line is reported: " + err[-800:])
    check(len(bad) == 6 and all("missing.glb" in e["error"] for e in bad),
          "the missing scene's 6 items fail naming the file: %r" % [e.get("error") for e in bad][:2])
    check(len(good) == 12, "the other 12 items are rendered: %d" % len(good))
    rc, _, err = run(lpvd, job, "--out", out, "--progress", "lines")
    check(rc == 1 and "6 failed" in err and "12 skipped" in err, "a re-run retries only the failed: " + err[-500:])


def manifest_lines_tolerant(out):
    lines = []
    for name in sorted(os.listdir(out)):
        if name.startswith("manifest-"):
            for line in open(os.path.join(out, name)):
                try:
                    e = json.loads(line)
                except ValueError:
                    continue
                lines.append(e)
    return lines


def case_errors(lpvd, source, tmp):
    outside = os.path.join(os.path.dirname(tmp.rstrip("/")), "outside-%d.glb" % os.getpid())
    shutil.copy(os.path.join(source, "scenes", "courtyard.glb"), outside)
    os.symlink(outside, os.path.join(tmp, "link.glb"))
    cases = [
        ("[1, 2]", "expected a JSON object"),
        ('{"scenes": []}', "lpvd_batch"),
        ('{"lpvd_batch": 2}', "lpvd_batch"),
        ('{"lpvd_batch": 1, "scene": []}', 'unknown key "scene"'),
        ('{"lpvd_batch": 1, "scenes": [{"path": "../x.glb"}]}', "scenes[0].path"),
        ('{"lpvd_batch": 1, "scenes": [{"path": "/etc/passwd"}]}', "scenes[0].path"),
        ('{"lpvd_batch": 1, "scenes": [{"name": "a/b"}]}', "scenes[0].name"),
        ('{"lpvd_batch": 1, "scenes": [{}, {}]}', 'two entries are named "cornell"'),
        ('{"lpvd_batch": 1, "settings": [{"grid": 0}]}', "settings[0].grid"),
        ('{"lpvd_batch": 1, "settings": [{"iterations": 2.5}]}', "settings[0].iterations"),
        ('{"lpvd_batch": 1, "settings": [{"colour": 1}]}', 'unknown key "colour"'),
        ('{"lpvd_batch": 1, "settings": [{"technique": "rtx"}]}', "settings[0].technique"),
        ('{"lpvd_batch": 1, "cameras": [{"eye": [0, 0, 1]}]}', "cameras[0].target"),
        ('{"lpvd_batch": 1, "cameras": [{"fov_deg": 180}]}', "cameras[0].fov_deg"),
        ('{"lpvd_batch": 1, "cameras": [{"orbit": {"views": 0}}]}', "cameras[0].orbit"),
        ('{"lpvd_batch": 1, "lights": [{"lights": [{"id": "a", "type": "laser", "intensity": 1}]}]}',
         "lights[0].lights[0].type"),
        ('{"lpvd_batch": 1, "scenes": [{"times": [0]}]}', "scenes[0].times"),
        ('{"lpvd_batch": 1, "scenes": [{"path": "a.glb", "times": [1, 1]}]}', "scenes[0].times[1]"),
        ('{"lpvd_batch": 1, "outputs": ["gif"]}', "outputs[0]"),
        ('{"lpvd_batch": 1, "size": [0, 10]}', "size"),
        ('{"lpvd_batch": 1, "cameras": [{"orbit": {"views": 3600}}], "settings": [' +
         ",".join('{"name": "s%d"}' % i for i in range(300)) + "]}", "more than 1000000 items"),
    ]
    for i, (text, want) in enumerate(cases):
        path = os.path.join(tmp, "bad%d.json" % i)
        with open(path, "w") as f:
            f.write(text)
        rc, _, err = run(lpvd, path, "--list")
        check(rc == 2 and want in err, "bad job %d refused naming %r: rc %d, %s" % (i, want, rc, err.strip()))
    # a symbolic link out of the job's folder: refused when the item runs
    path = os.path.join(tmp, "link.json")
    with open(path, "w") as f:
        json.dump({"lpvd_batch": 1, "size": [16, 16], "scenes": [{"path": "link.glb"}]}, f)
    rc, _, err = run(lpvd, path, "--out", os.path.join(tmp, "o"), "--progress", "lines")
    lines = manifest_lines(os.path.join(tmp, "o"))
    check(rc == 1 and lines and "leaves the job file's folder" in lines[0].get("error", ""),
          "a scene linked from outside the job's folder is refused: %s" % err[-500:])
    os.remove(outside)
    rc, _, err = run(lpvd, os.path.join(tmp, "none.json"), "--list")
    check(rc == 2 and "none.json" in err, "a missing job file is named: " + err)
    rc, _, err = run(lpvd, path, "--shard", "3/3", "--list")
    check(rc == 2 and "3/3" in err, "--shard 3/3 is refused: " + err)


def case_schema(lpvd, source, tmp):
    import jsonschema  # python3-jsonschema (scripts/install-deps.sh)
    with open(os.path.join(source, "docs", "batch.schema.json")) as f:
        schema = json.load(f)
    jsonschema.Draft202012Validator.check_schema(schema)
    v = jsonschema.Draft202012Validator(schema)
    example = os.path.join(source, "scenes", "batch-example.json")
    with open(example) as f:
        ex = json.load(f)
    errors = [e.message for e in v.iter_errors(ex)]
    check(not errors, "the example job is valid against the schema: %r" % errors)
    items = listed(lpvd, example)
    check(len(items) == 16, "the example job expands to 16 items: %d" % len(items))
    # what the schema refuses, lpvd refuses
    bad = [
        {"lpvd_batch": 1, "scenes": [{"path": "../up.glb"}]},
        {"lpvd_batch": 1, "scenes": [{"name": ".hidden"}]},
        {"lpvd_batch": 1, "cameras": [{"camera": 0, "eye": [0, 0, 0], "target": [0, 0, 1]}]},
        {"lpvd_batch": 1, "outputs": []},
        {"lpvd_batch": 1, "size": [10]},
        {"lpvd_batch": 1, "extra": 1},
        {"lpvd_batch": 1, "scenes": [{"path": "a.glb", "animation": "walk"}]},
    ]
    for i, j in enumerate(bad):
        check(not v.is_valid(j), "schema refuses bad job %d" % i)
        path = os.path.join(tmp, "schema-bad%d.json" % i)
        with open(path, "w") as f:
            json.dump(j, f)
        rc, _, err = run(lpvd, path, "--list")
        check(rc == 2, "lpvd refuses bad job %d too: %s" % (i, err.strip()))


def gltf_box(path, translation=None, animate_to=None):
    """A 1 m box (12 triangles) on a node over a 6 m floor, lit by a point
    light; the box's node at `translation`, or animated from x = -1.5 to
    animate_to over 1 s (LINEAR)."""
    import base64
    import struct
    def box(lo, hi):
        (x0, y0, z0), (x1, y1, z1) = lo, hi
        c = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0), (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
        faces = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (3, 7, 6, 2), (0, 4, 7, 3), (1, 2, 6, 5)]
        v = []
        for f in faces:  # counter-clockwise seen from outside
            for t in ((f[0], f[1], f[2]), (f[0], f[2], f[3])):
                v += [c[i] for i in t]
        return v
    meshes = [box((-3, -0.1, -3), (3, 0, 3)), box((-0.5, 0, -0.5), (0.5, 1, 0.5))]
    blob = b""
    accessors, views, gmeshes = [], [], []
    for m in meshes:
        data = b"".join(struct.pack("<3f", *p) for p in m)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)})
        accessors.append({"bufferView": len(views) - 1, "componentType": 5126, "count": len(m), "type": "VEC3",
                          "min": [min(p[i] for p in m) for i in range(3)], "max": [max(p[i] for p in m) for i in range(3)]})
        gmeshes.append({"primitives": [{"attributes": {"POSITION": len(accessors) - 1}, "material": len(gmeshes)}]})
        blob += data
    doc = {"asset": {"version": "2.0"}, "scene": 0,
           "scenes": [{"nodes": [0, 1, 2, 3]}],
           "nodes": [{"mesh": 0}, {"mesh": 1, "translation": translation or [-1.5, 0, 0]},
                     {"camera": 0, "translation": [0, 3, 7], "rotation": [-0.2164, 0, 0, 0.9763]},
                     {"extensions": {"KHR_lights_punctual": {"light": 0}}, "translation": [1, 4, 1]}],
           "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1, "aspectRatio": 1.0}}],
           "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0}},
                         {"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.2, 0.1, 1], "metallicFactor": 0}}],
           "meshes": gmeshes, "accessors": accessors, "bufferViews": views,
           "extensionsUsed": ["KHR_lights_punctual"],
           "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 3000.0}]}}}
    if animate_to is not None:
        keys = struct.pack("<2f", 0.0, 1.0) + struct.pack("<6f", -1.5, 0, 0, *animate_to)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": 8})
        views.append({"buffer": 0, "byteOffset": len(blob) + 8, "byteLength": 24})
        accessors.append({"bufferView": len(views) - 2, "componentType": 5126, "count": 2, "type": "SCALAR",
                          "min": [0.0], "max": [1.0]})
        accessors.append({"bufferView": len(views) - 1, "componentType": 5126, "count": 2, "type": "VEC3"})
        doc["animations"] = [{"name": "slide", "samplers": [{"input": len(accessors) - 2, "output": len(accessors) - 1}],
                              "channels": [{"sampler": 0, "target": {"node": 1, "path": "translation"}}]}]
        blob += keys
    doc["buffers"] = [{"byteLength": len(blob),
                       "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}]
    with open(path, "w") as f:
        json.dump(doc, f)


def case_features(lpvd, source, tmp):
    gltf_box(os.path.join(tmp, "anim.gltf"), animate_to=[1.5, 0, 0])
    gltf_box(os.path.join(tmp, "posed.gltf"), translation=[0.75, 0, 0])
    with open(os.path.join(tmp, "pts.csv"), "w") as f:
        f.write("# px,py,pz,nx,ny,nz\n0,0.01,2,0,1,0\n2,0.01,-2,0,1,0\n0.5,0.5,0.51,0,0,1\n")
    job = {"lpvd_batch": 1, "size": [64, 64],
           "scenes": [{"path": "anim.gltf", "animation": "slide", "times": [0, 0.75, 1, 2]}, {"path": "posed.gltf"}],
           "lights": [{"name": "file"},
                      {"name": "blue", "lights": [{"id": "b", "type": "point", "intensity": 500.0,
                                                   "color": [0.2, 0.4, 1.0], "position": [-1, 3, 2]}]}],
           "settings": [{"name": "iv", "technique": "iv", "iv_rays": 32}],
           "outputs": ["png", "ao", "volume", {"points": "pts.csv"}]}
    path = os.path.join(tmp, "job.json")
    with open(path, "w") as f:
        json.dump(job, f)
    out = os.path.join(tmp, "out")
    rc, _, err = run(lpvd, path, "--out", out, "--progress", "lines")
    check(rc == 0, "the features job runs: " + err[-1500:])
    d = digests(out)
    def h(rel):
        return d.get(rel)
    check(h("anim@0.75/default/file/iv.png") == h("posed/default/file/iv.png") is not None,
          "the frame at t = 0.75 s is the file posed there, byte for byte")
    check(h("anim@0/default/file/iv.png") != h("anim@0.75/default/file/iv.png"), "the box moved between 0 and 0.75 s")
    check(h("anim@1/default/file/iv.png") != h("anim@0.75/default/file/iv.png"), "and again by 1 s")
    check(h("anim@2/default/file/iv.png") == h("anim@1/default/file/iv.png") is not None,
          "after the last keyframe (1 s) the pose stays: 2 s renders as 1 s")
    check(h("posed/default/blue/iv.png") != h("posed/default/file/iv.png"), "the light override changes the image")
    entries = {e["id"]: e for e in manifest_lines(out)}
    check(len(entries) == 10 and all(e["status"] == "ok" for e in entries.values()), "10 items ok")
    e = entries.get("anim@0.75/default/file/iv", {})
    check(e.get("time") == 0.75 and {o["kind"] for o in e.get("outputs", [])} ==
          {"image", "ao", "points", "volume", "volume_header"}, "the manifest names the time and the outputs: %r" % e)
    with open(os.path.join(out, "posed/default/file/iv-points.csv")) as f:
        rows = [line.strip().split(",") for line in f if line.strip() and not line.startswith(("#", "E_"))]
    vals = [float(v) for r in rows for v in r]
    check(len(rows) == 3 and all(v >= 0 and v == v and v < 1e6 for v in vals) and sum(vals) > 0,
          "irradiance at the 3 points, finite, some light: %r" % rows)
    # the volume file decodes with the Python client and its SPEC lookup gives the engine's irradiance
    sys.path.insert(0, os.path.join(source, "clients", "python"))
    import lpvd_client
    with open(os.path.join(out, "posed/default/file/iv-volume.json")) as f:
        header = json.load(f)
    with open(os.path.join(out, "posed/default/file/iv-volume.bin"), "rb") as f:
        vol = lpvd_client.Volume(header, f.read())
    pts = [((0, 0.01, 2), (0, 1, 0)), ((2, 0.01, -2), (0, 1, 0)), ((0.5, 0.5, 0.51), (0, 0, 1))]
    for (p, nrm), row in zip(pts, rows):
        want = [float(v) for v in row]
        got = vol.irradiance(p, nrm)
        check(all(abs(g - w) <= 1e-4 * max(1.0, abs(w)) + 1e-3 * max(want) for g, w in zip(got, want)),
              "the volume's lookup at %r gives the engine's irradiance: %r vs %r" % (p, got, want))
    # ao without the imperfect volume is refused per item, naming why
    job["settings"] = [{"name": "lpv", "technique": "lpv"}]
    with open(path, "w") as f:
        json.dump(job, f)
    rc, _, err = run(lpvd, path, "--out", os.path.join(tmp, "o2"), "--progress", "lines")
    lines = manifest_lines(os.path.join(tmp, "o2"))
    check(rc == 1 and lines and all("ao output needs technique iv" in e.get("error", "") for e in lines),
          "the ao output with technique lpv fails each item, saying why")
    # an animation the file does not have
    job["settings"] = [{"name": "iv", "technique": "iv"}]
    job["scenes"] = [{"path": "anim.gltf", "animation": "walk", "times": [0]}]
    with open(path, "w") as f:
        json.dump(job, f)
    rc, _, err = run(lpvd, path, "--out", os.path.join(tmp, "o3"), "--progress", "lines")
    lines = manifest_lines(os.path.join(tmp, "o3"))
    check(rc == 1 and lines and "walk" in lines[0].get("error", ""), "an unknown animation is named: %r" %
          [e.get("error") for e in lines][:1])


def case_links(lpvd, source, tmp):
    victims = os.path.join(tmp, "victims")
    os.makedirs(os.path.join(victims, "dir"))
    vfile = os.path.join(victims, "file")

    def reset_victim():
        with open(vfile, "w") as f:
            f.write("precious\n")

    def victim_intact(what):
        with open(vfile, "rb") as f:
            check(f.read() == b"precious\n", what + ": the link's target file is unchanged")
        check(os.listdir(os.path.join(victims, "dir")) == [], what + ": nothing written into the linked folder")

    job = {"lpvd_batch": 1, "size": [32, 32], "scenes": [{"name": "cornell"}],
           "cameras": [{"name": "file"}], "settings": [{"name": "a", "preset": "fast"}, {"name": "b", "preset": "fast"}],
           "outputs": ["png"]}
    path = os.path.join(tmp, "job.json")
    with open(path, "w") as f:
        json.dump(job, f)
    ids = [i[1] for i in listed(lpvd, path)]
    check(len(ids) == 2 and ids[0].startswith("cornell/"), "the job's items: %r" % ids)
    folder = os.path.dirname(ids[1])  # cornell/...: the items' folder

    # 1. the manifest is a link: refused before anything is rendered
    reset_victim()
    out = os.path.join(tmp, "o1")
    os.makedirs(out)
    os.symlink(vfile, os.path.join(out, "manifest-0-of-1.jsonl"))
    rc, _, err = run(lpvd, path, "--out", out, "--progress", "off")
    check(rc != 0 and "manifest-0-of-1.jsonl" in err and "symbolic link" in err,
          "a linked manifest is refused, naming it: rc %d, %s" % (rc, err.strip()[-300:]))
    victim_intact("linked manifest")

    # 2. the items' top folder is a link; then item b's output is a link
    reset_victim()
    out = os.path.join(tmp, "o2")
    os.makedirs(out)
    os.symlink(os.path.join(victims, "dir"), os.path.join(out, "cornell"))
    rc, _, err = run(lpvd, path, "--out", out, "--progress", "off")
    lines = manifest_lines(out)
    check(rc == 1 and len(lines) == 2 and all("symbolic link" in e.get("error", "") for e in lines),
          "items under a linked folder fail, naming the link: rc %d, %r" % (rc, [e.get("error") for e in lines]))
    victim_intact("linked item folder")
    os.unlink(os.path.join(out, "cornell"))
    os.makedirs(os.path.join(out, folder))
    b = os.path.join(out, ids[1] + ".png")
    os.symlink(vfile, b)
    if os.path.lexists(os.path.join(out, "contact.png")):
        os.unlink(os.path.join(out, "contact.png"))
    os.symlink(vfile, os.path.join(out, "contact.png"))
    rc, _, err = run(lpvd, path, "--out", out, "--progress", "off")
    check(rc == 0 and not os.path.islink(b) and os.path.getsize(b) > 0,
          "a link in place of an output is replaced by the image: rc %d, %s" % (rc, err.strip()[-300:]))
    victim_intact("linked output")

    # 3. the report: a linked thumbs/ is refused; a linked contact.png is replaced
    shutil.rmtree(os.path.join(out, "thumbs"), ignore_errors=True)
    os.symlink(os.path.join(victims, "dir"), os.path.join(out, "thumbs"))
    rc, _, err = run(lpvd, path, "--out", out, "--report", "--progress", "off")
    check(rc != 0 and "thumbs" in err and "symbolic link" in err,
          "a linked thumbs/ is refused, naming it: rc %d, %s" % (rc, err.strip()[-300:]))
    victim_intact("linked thumbs/")
    os.unlink(os.path.join(out, "thumbs"))
    rc, _, err = run(lpvd, path, "--out", out, "--report", "--progress", "off")
    contact = os.path.join(out, "contact.png")
    check(rc == 0 and not os.path.islink(contact) and os.path.getsize(contact) > 0,
          "a link in place of contact.png is replaced by the sheet: rc %d, %s" % (rc, err.strip()[-300:]))
    victim_intact("linked contact.png")

    # 4. a FIFO as the points file: refused at once, not waited on
    fifo_job = dict(job, outputs=["png", {"points": "pts.csv"}])
    os.mkfifo(os.path.join(tmp, "pts.csv"))
    with open(path, "w") as f:
        json.dump(fifo_job, f)
    t0 = time.monotonic()
    try:
        rc, _, err = run(lpvd, path, "--out", os.path.join(tmp, "o4"), "--progress", "off", timeout=60)
    except subprocess.TimeoutExpired:
        rc, err = None, "still running after 60 s"
    check(rc not in (None, 0) and "pts.csv" in err and "not a regular file" in err,
          "a FIFO as the points file is refused in %.1f s: rc %r, %s" % (time.monotonic() - t0, rc, err.strip()[-300:]))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--lpvd", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("case", choices=["shards", "resume", "failures", "errors", "features", "schema", "links"])
    a = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="lpvd-batch-")
    try:
        globals()["case_" + a.case](os.path.abspath(a.lpvd), os.path.abspath(a.source), tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    if FAILS:
        print("%d check(s) failed" % len(FAILS))
        return 1
    print("ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
