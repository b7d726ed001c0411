#!/usr/bin/env python3
"""test_k8s_manifests.py - the Kubernetes manifests of docker/k8s/ against the
facts they rely on (docs/deploy.md).

Static checks, always:
  - every docker/k8s/*.yaml parses (multi-document) and every document has
    apiVersion, kind and metadata.name;
  - every container image is the name docker/README.md's `docker build ... -t
    NAME` builds (the one place that name is decided);
  - docker/Dockerfile's ENTRYPOINT is the lpvd binary of its own build, and
    the manifests run that binary (and lpvctl from the same build);
  - each Indexed Job runs `lpvd batch` directly as the image's ENTRYPOINT (no
    command, no shell around it, so lpvd's exit status is the container's),
    with LPVD_SHARDS = spec.completions, its job file and --out on claims that
    the toolbox pod mounts at the same paths; its podFailurePolicy, evaluated
    as Kubernetes does, ignores exit status 3 (stopped by SIGTERM, resumable)
    and the DisruptionTarget condition, fails the Job on 2 (bad job file) and
    counts 1 (an item failed) and 137 against backoffLimitPerIndex (>= 1);
    a GPU Job asks for the NVIDIA graphics capability (EGL);
  - the daemon's workload runs `lpvd serve`, has readiness and liveness
    probes, and its token, port and headless Service agree.

Behaviour, when LPVD_BINARY (and, for the daemon, LPVCTL_BINARY) is set
(ctest sets both):
  - each Job's container argv is run with the built lpvd, its mount paths
    (/scenes, /out) moved to temporary folders, and the environment the
    manifest sets (LPVD_SHARDS; LP_NUM_THREADS from limits.cpu; a GPU Job's
    LPVD_GL_BACKEND=egl-device left out, the test having no GPU node) plus
    JOB_COMPLETION_INDEX = 0 .. completions-1 in turn, on a two-item job:
    every index exits 0 (most shards are empty), the shards' manifests
    together hold each item once, and the toolbox's end-of-job command
    (the same argv + --merge --report, no shard) merges and reports them;
  - one index of a larger job (4 items per shard) gets SIGTERM as soon as its
    first manifest line is written: it exits 3, a status the failure policy
    ignores, with some but not all of its items recorded, and run again it
    resumes and exits 0 with each of its items recorded once;
  - `lpvd serve` starts with the manifest's own args and the probes' commands
    pass against it, the readiness probe fails with a wrong token while
    liveness holds, and both fail once it has stopped.

Needs PyYAML (Debian: python3-yaml, in scripts/install-deps.sh). Exit 0 when
every check passes, 1 otherwise (each failure printed).
"""
import glob
import json
import math
import os
import re
import shlex
import signal
import socket
import subprocess
import sys
import tempfile
import time

ROOT = os.environ.get("LPVD_SOURCE_DIR") or os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
K8S = os.path.join(ROOT, "docker", "k8s")

try:
    import yaml
except ImportError:
    print("test_k8s_manifests: PyYAML is missing (Debian: apt-get install python3-yaml, "
          "or sh scripts/install-deps.sh)", file=sys.stderr)
    sys.exit(1)

failures = []


def check(cond, msg):
    if not cond:
        failures.append(msg)
    return cond


def read(path):
    with open(os.path.join(ROOT, path), encoding="utf-8") as f:
        return f.read()


# --- the facts the manifests rely on --------------------------------------

def image_name():
    """The NAME of every `docker build ... -t NAME` in docker/README.md (one)."""
    text = read("docker/README.md")
    names = set()
    for line in text.splitlines():
        if re.match(r"\s*docker build\b", line):
            argv = shlex.split(line.split("#", 1)[0])
            for i, a in enumerate(argv):
                if a in ("-t", "--tag") and i + 1 < len(argv):
                    names.add(argv[i + 1])
                elif a.startswith("--tag="):
                    names.add(a[len("--tag="):])
    if not check(len(names) == 1, f"docker/README.md: expected one `docker build -t NAME`, found {sorted(names)}"):
        return None
    name = names.pop()
    for line in text.splitlines():
        if re.match(r"\s*docker run\b", line):
            check(name in shlex.split(line.split("#", 1)[0]),
                  f"docker/README.md: `{line.strip()}` does not run the image it builds ({name})")
    return name


def dockerfile():
    """(ENTRYPOINT's binary, the build folder in the image) from docker/Dockerfile."""
    text = read("docker/Dockerfile").replace("\\\n", " ")
    workdir = "/"
    build_dir = None
    entry = None
    for line in text.splitlines():
        line = line.strip()
        m = re.match(r"WORKDIR\s+(\S+)", line)
        if m:
            workdir = os.path.join(workdir, m.group(1))
        m = re.match(r"RUN\s+(.*)", line)
        if m and build_dir is None:
            b = re.search(r"cmake\s+-S\s+\S+\s+-B\s+(\S+)", m.group(1))
            if b:
                build_dir = os.path.normpath(os.path.join(workdir, b.group(1)))
                t = re.search(r"cmake\s+--build\s+\S+(.*)", m.group(1))
                targets = re.findall(r"--target\s+([^-&|;]+)", t.group(1)) if t else []
                if targets:
                    named = " ".join(targets).split()
                    check("lpvd" in named and "lpvctl" in named,
                          f"docker/Dockerfile builds only {named}; the manifests run lpvd and lpvctl")
        m = re.match(r"ENTRYPOINT\s+(.*)", line)
        if m:
            try:
                entry = json.loads(m.group(1))
            except ValueError:
                entry = None
            check(isinstance(entry, list) and len(entry) == 1,
                  f"docker/Dockerfile: ENTRYPOINT must be the exec form of one binary, got {m.group(1)}")
    if not check(build_dir, "docker/Dockerfile: no `cmake -S . -B DIR` found"):
        return None, None
    want = os.path.join(build_dir, "server", "lpvd")
    check(re.search(r"add_executable\(lpvd\b", read("server/CMakeLists.txt")) is not None,
          "server/CMakeLists.txt no longer builds lpvd (the ENTRYPOINT's build/server/lpvd)")
    if not check(isinstance(entry, list) and entry == [want],
                 f"docker/Dockerfile: ENTRYPOINT {entry} is not the lpvd it builds ({want})"):
        return None, build_dir
    return want, build_dir


def lpvctl_path(build_dir):
    check(re.search(r"RUNTIME_OUTPUT_DIRECTORY \$\{CMAKE_CURRENT_BINARY_DIR\}/lpvctl\)",
                    read("clients/CMakeLists.txt")) is not None,
          "clients/CMakeLists.txt no longer puts lpvctl in build/clients/lpvctl/")
    return os.path.join(build_dir, "clients", "lpvctl", "lpvctl")


# --- the manifests ----------------------------------------------------------

def load_manifests():
    docs = []
    files = sorted(glob.glob(os.path.join(K8S, "*.yaml")) + glob.glob(os.path.join(K8S, "*.yml")))
    check(files, "no docker/k8s/*.yaml")
    for path in files:
        rel = os.path.relpath(path, ROOT)
        try:
            with open(path, encoding="utf-8") as f:
                loaded = [d for d in yaml.safe_load_all(f) if d is not None]
        except yaml.YAMLError as e:
            check(False, f"{rel}: does not parse: {e}")
            continue
        check(loaded, f"{rel}: no documents")
        for i, d in enumerate(loaded):
            where = f"{rel} document {i + 1}"
            if not check(isinstance(d, dict), f"{where}: not a mapping"):
                continue
            check(isinstance(d.get("apiVersion"), str) and d["apiVersion"], f"{where}: no apiVersion")
            check(isinstance(d.get("kind"), str) and d["kind"], f"{where}: no kind")
            name = (d.get("metadata") or {}).get("name")
            check(isinstance(name, str) and name, f"{where}: no metadata.name")
            docs.append((f"{rel} {d.get('kind')}/{name}", d))
    return docs


def pod_spec(d):
    kind = d.get("kind")
    if kind == "Pod":
        return d.get("spec") or {}
    if kind in ("Job", "Deployment", "StatefulSet", "DaemonSet", "ReplicaSet"):
        return ((d.get("spec") or {}).get("template") or {}).get("spec") or {}
    if kind == "CronJob":
        return ((((d.get("spec") or {}).get("jobTemplate") or {}).get("spec") or {}).get("template") or {}).get("spec") or {}
    return None


def containers(spec):
    return list(spec.get("initContainers") or []) + list(spec.get("containers") or [])


def env_value(c, name):
    for e in c.get("env") or []:
        if e.get("name") == name:
            return e.get("value")
    return None


def effective_argv(c, entry):
    """What the container runs: ENTRYPOINT + args without a command, else
    command + args."""
    cmd = c.get("command")
    args = list(c.get("args") or [])
    return [entry] + args if not cmd else list(cmd) + args


def check_images(docs, name):
    for where, d in docs:
        spec = pod_spec(d)
        if spec is None:
            continue
        cs = containers(spec)
        check(cs, f"{where}: no containers")
        for c in cs:
            check(c.get("image") == name,
                  f"{where}: container {c.get('name')} runs image {c.get('image')!r}, "
                  f"not {name!r} (docker/README.md's docker build -t)")


def policy_action(rules, container, exit_code, conditions=()):
    """The action a Job's podFailurePolicy takes for a failed pod whose
    container `container` exited with `exit_code` and which has the pod
    conditions `conditions` (types, status True), as Kubernetes decides it:
    the first rule that matches, else Count."""
    for r in rules:
        on_exit = r.get("onExitCodes")
        on_cond = r.get("onPodConditions")
        match = False
        if on_exit:
            name = on_exit.get("containerName")
            values = on_exit.get("values") or []
            if name is None or name == container:
                if on_exit.get("operator") == "In":
                    match = exit_code in values
                elif on_exit.get("operator") == "NotIn":
                    match = exit_code != 0 and exit_code not in values
        elif on_cond:
            match = any(p.get("type") in conditions and str(p.get("status", "True")) == "True" for p in on_cond)
        if match:
            return r.get("action")
    return "Count"


def check_jobs(docs, entry):
    """The static checks of each Indexed Job; returns [(where, job, container,
    argv)] of the Jobs running `lpvd batch`, for check_batch_live."""
    jobs = [(w, d) for w, d in docs if d.get("kind") == "Job"]
    indexed = [(w, d) for w, d in jobs if (d.get("spec") or {}).get("completionMode") == "Indexed"]
    check(indexed, "docker/k8s: no Indexed Job (completionMode: Indexed)")
    toolbox = [(w, d) for w, d in docs if d.get("kind") == "Pod"]
    check(toolbox, "docker/k8s: no Pod (the toolbox of docs/deploy.md)")
    policies = {}
    found = []
    for where, d in indexed:
        spec = d["spec"]
        tmpl = pod_spec(d)
        completions = spec.get("completions")
        check(isinstance(completions, int) and completions >= 1, f"{where}: spec.completions {completions!r}")
        par = spec.get("parallelism", 1)
        check(isinstance(par, int) and 1 <= par <= (completions or 0),
              f"{where}: parallelism {par!r} outside 1..completions")
        check(tmpl.get("restartPolicy") == "Never",
              f"{where}: restartPolicy must be Never (backoffLimitPerIndex, podFailurePolicy)")
        check(spec.get("podReplacementPolicy") == "Failed",
              f"{where}: podReplacementPolicy must be Failed: two pods of one index would append to one manifest")
        grace = tmpl.get("terminationGracePeriodSeconds")
        check(isinstance(grace, int) and grace >= 60,
              f"{where}: terminationGracePeriodSeconds {grace!r}: must let the item in flight finish (>= 60)")
        batch = []
        for c in tmpl.get("containers") or []:
            argv = effective_argv(c, entry)
            if "batch" in argv:
                batch.append((c, argv))
        if not check(len(batch) == 1, f"{where}: expected one container running `lpvd batch`, found {len(batch)}"):
            continue
        c, argv = batch[0]
        # lpvd itself, not a shell around it: its exit status (3 on SIGTERM
        # with items left) is then the container's, and SIGTERM reaches it
        check(not c.get("command") or list(c["command"]) == [entry],
              f"{where}: container {c.get('name')} has command {c.get('command')}: run the image's ENTRYPOINT "
              f"({entry}) directly, so that lpvd's exit status is the container's")
        if not check(argv[0] == entry and argv[1:2] == ["batch"],
                     f"{where}: runs {argv[:2]}, not the image's lpvd ({entry}) with `batch`"):
            continue
        shards = env_value(c, "LPVD_SHARDS")
        check(shards is not None and str(shards) == str(completions),
              f"{where}: LPVD_SHARDS {shards!r} != spec.completions {completions!r}")
        check("--shard" not in argv, f"{where}: --shard on the command line overrides JOB_COMPLETION_INDEX")
        if not check("--out" in argv[:-1], f"{where}: lpvd batch without --out DIR"):
            continue
        positional = [a for i, a in enumerate(argv[2:], 2) if not a.startswith("-") and argv[i - 1] != "--out"]
        if not check(len(positional) == 1, f"{where}: expected one job file after `batch`, got {positional}"):
            continue
        # the job file and --out on the claims, and the toolbox pod (where
        # docs/deploy.md runs --list, --merge and --report) sees them at the
        # same paths
        claims = {v.get("name"): (v.get("persistentVolumeClaim") or {}).get("claimName") for v in tmpl.get("volumes") or []}
        mounts = c.get("volumeMounts") or []

        def mount_of(path, ms):
            ms = [m for m in ms if path.startswith(m.get("mountPath", "").rstrip("/") + "/")]
            return max(ms, key=lambda m: len(m["mountPath"])) if ms else None

        for what, path, writable in (("the job file", positional[0], False),
                                     ("--out", argv[argv.index("--out") + 1], True)):
            m = mount_of(path, mounts)
            if not check(m and claims.get(m.get("name")), f"{where}: {what} {path} is not on a mounted claim"):
                continue
            if writable:
                check(not m.get("readOnly"), f"{where}: --out {path} is on a read-only mount")
            for twhere, td in toolbox:
                ts = pod_spec(td)
                tclaims = {v.get("name"): (v.get("persistentVolumeClaim") or {}).get("claimName")
                           for v in ts.get("volumes") or []}
                tm = [mount_of(path, tc.get("volumeMounts") or []) for tc in ts.get("containers") or []]
                check(any(x and x["mountPath"] == m["mountPath"] and tclaims.get(x.get("name")) == claims[m["name"]]
                          for x in tm),
                      f"{twhere}: does not mount claim {claims[m['name']]} at {m['mountPath']} as {where} does "
                      f"(docs/deploy.md reaches {path} there)")
        # the failure policy, evaluated as Kubernetes does
        rules = (spec.get("podFailurePolicy") or {}).get("rules") or []
        name = c.get("name")
        for r in rules:
            cn = (r.get("onExitCodes") or {}).get("containerName")
            check(cn is None or cn == name,
                  f"{where}: podFailurePolicy names container {cn!r}, the batch container is {name!r}")
        want = [(3, (), "Ignore", "3 (stopped by SIGTERM with items left: the index runs again and resumes)"),
                (2, (), "FailJob", "2 (a bad command line or job file: every retry fails the same way)"),
                (1, (), "Count", "1 (an item failed: counted against backoffLimitPerIndex, the index retried)"),
                (137, (), "Count", "137 (killed: out of memory, or past the grace period)")]
        want += [(code, ("DisruptionTarget",), "Ignore", f"{code} with condition DisruptionTarget (pre-empted, evicted)")
                 for code in (1, 3, 137, 143)]
        for code, conds, action, what in want:
            got = policy_action(rules, name, code, conds)
            check(got == action, f"{where}: podFailurePolicy takes {got} for exit status {what}, not {action}")
        limit = spec.get("backoffLimitPerIndex")
        check(isinstance(limit, int) and limit >= 1,
              f"{where}: backoffLimitPerIndex {limit!r}: an index whose items failed (exit 1) must be retried")
        policies[where] = rules
        limits = (c.get("resources") or {}).get("limits") or {}
        if "nvidia.com/gpu" in limits:
            caps = env_value(c, "NVIDIA_DRIVER_CAPABILITIES") or ""
            check("graphics" in caps.split(",") or caps == "all",
                  f"{where}: a GPU Job without graphics in NVIDIA_DRIVER_CAPABILITIES gets no NVIDIA EGL")
        found.append((where, d, c, argv))
    check(len({json.dumps(p, sort_keys=True) for p in policies.values()}) <= 1,
          f"the Jobs' podFailurePolicy rules differ: {sorted(policies)}")
    return found


# --- lpvd batch, live ---------------------------------------------------------

SMALL_JOB = {"lpvd_batch": 1, "size": [32, 32],
             "settings": [{"name": "a", "preset": "fast"}, {"name": "b", "preset": "fast", "iterations": 2}]}


class Pod:
    """A Job's batch container run here: its argv with the mounts' paths
    rewritten to folders of `tmp`, the ENTRYPOINT replaced by the built lpvd,
    and the environment the manifest sets (plus what Kubernetes adds)."""

    def __init__(self, where, job, c, argv, lpvd, tmp):
        self.where = where
        self.lpvd = lpvd
        self.shards = job["spec"]["completions"]
        roots = {m["mountPath"].rstrip("/"): os.path.join(tmp, m["name"]) for m in c.get("volumeMounts") or []}
        for r in roots.values():
            os.makedirs(r, exist_ok=True)

        def local(a):
            for mp in sorted(roots, key=len, reverse=True):
                if a == mp or a.startswith(mp + "/"):
                    return roots[mp] + a[len(mp):]
            return a

        self.args = [local(a) for a in argv[1:]]
        self.out = self.args[self.args.index("--out") + 1]
        self.job_file = [a for i, a in enumerate(self.args[1:], 1)
                         if not a.startswith("-") and self.args[i - 1] != "--out"][0]
        # the environment: this process's, less what would pick the shard or
        # the backend, then the manifest's env
        self.base = {k: v for k, v in os.environ.items()
                     if k not in ("JOB_COMPLETION_INDEX", "LPVD_SHARDS", "LPVD_GL_BACKEND")}
        self.env = dict(self.base)
        gpu = "nvidia.com/gpu" in ((c.get("resources") or {}).get("limits") or {})
        for e in c.get("env") or []:
            if gpu and e.get("name") == "LPVD_GL_BACKEND":
                continue  # egl-device needs the GPU node; the shards and statuses are the same on llvmpipe
            if "value" in e:
                self.env[e["name"]] = str(e["value"])
            ref = (e.get("valueFrom") or {}).get("resourceFieldRef") or {}
            if ref.get("resource") == "limits.cpu":  # whole CPUs, rounded up (divisor 1)
                cpu = str(((c.get("resources") or {}).get("limits") or {}).get("cpu", "1"))
                self.env[e["name"]] = str(math.ceil(int(cpu[:-1]) / 1000 if cpu.endswith("m") else float(cpu)))

    def write_job(self, job):
        os.makedirs(os.path.dirname(self.job_file), exist_ok=True)
        with open(self.job_file, "w") as f:
            json.dump(job, f)

    def index_env(self, i):
        return dict(self.env, JOB_COMPLETION_INDEX=str(i))

    def run(self, i, extra=(), env=None):
        r = subprocess.run([self.lpvd] + self.args + list(extra), env=env or self.index_env(i),
                           capture_output=True, text=True, timeout=120)
        return r.returncode, (r.stdout + r.stderr).strip()

    def ids(self, env):
        """The items `--list` prints for `env`: [id]."""
        r = subprocess.run([self.lpvd, "batch", self.job_file, "--list"], env=env,
                           capture_output=True, text=True, timeout=60)
        check(r.returncode == 0, f"{self.where}: lpvd batch --list exited {r.returncode}: {r.stderr.strip()}")
        return [line.split("\t")[1] for line in r.stdout.splitlines() if line.count("\t") == 2]

    def manifest(self, i):
        return os.path.join(self.out, f"manifest-{i}-of-{self.shards}.jsonl")

    def lines(self, paths):
        out = []
        for p in paths:
            if os.path.exists(p):
                with open(p) as f:
                    out += [json.loads(line) for line in f if line.strip()]
        return out


def check_batch_live(found, lpvd):
    for where, job, c, argv in found:
        rules = (job["spec"].get("podFailurePolicy") or {}).get("rules") or []
        # every index of the Job, one after the other, on a two-item job:
        # with more shards than items most shards are empty, and exit 0 too
        with tempfile.TemporaryDirectory() as tmp:
            pod = Pod(where, job, c, argv, lpvd, tmp)
            pod.write_job(SMALL_JOB)
            items = pod.ids(pod.base)
            check(len(items) == 2, f"{where}: the two-item job lists {items}")
            for i in range(pod.shards):
                rc, log = pod.run(i)
                check(rc == 0, f"{where}: index {i} of {pod.shards} exited {rc}, not 0: {log[-2000:]}")
            names = sorted(os.path.basename(p) for p in glob.glob(os.path.join(pod.out, "manifest*.jsonl")))
            check(names == sorted(os.path.basename(pod.manifest(i)) for i in range(pod.shards)),
                  f"{where}: the indexes wrote {names}, not manifest-I-of-{pod.shards}.jsonl for I = 0..{pod.shards - 1}")
            lines = pod.lines(glob.glob(os.path.join(pod.out, "manifest*.jsonl")))
            got = sorted(e.get("id") for e in lines)
            check(got == sorted(items), f"{where}: the shards' manifests hold {got}, not each of {items} once")
            check(all(e.get("status") == "ok" for e in lines), f"{where}: an item failed: {lines}")
            for e in lines:
                for o in e.get("outputs") or []:
                    check(os.path.isfile(os.path.join(pod.out, o.get("path", ""))),
                          f"{where}: {e.get('id')}: output {o.get('path')} missing")
            # the end of the job, as docs/deploy.md runs it in the toolbox pod
            rc, log = pod.run(0, ["--merge", "--report"], env=pod.base)
            check(rc == 0, f"{where}: --merge --report exited {rc}: {log[-2000:]}")
            merged = pod.lines([os.path.join(pod.out, "manifest.jsonl")])
            check(sorted(e.get("id") for e in merged) == sorted(items),
                  f"{where}: --merge wrote {[e.get('id') for e in merged]}, not {items}")
            for f in ("report.html", "contact.png"):
                check(os.path.isfile(os.path.join(pod.out, f)), f"{where}: --report wrote no {f}")
        # SIGTERM to one index of a larger job once its first item is
        # recorded: the item in flight finishes, exit 3, which the failure
        # policy ignores; the index run again resumes and exits 0
        with tempfile.TemporaryDirectory() as tmp:
            pod = Pod(where, job, c, argv, lpvd, tmp)
            pod.write_job({"lpvd_batch": 1, "size": [32, 32],
                           "cameras": [{"name": "o", "orbit": {"views": 4 * pod.shards}}],
                           "settings": [{"name": "fast", "preset": "fast"}]})
            per = [pod.ids(pod.index_env(i)) for i in range(pod.shards)]
            i = max(range(pod.shards), key=lambda k: len(per[k]))
            mine = per[i]
            if not check(len(mine) >= 3, f"{where}: the SIGTERM test needs an index with 3 items or more: {per}"):
                continue
            log = open(os.path.join(tmp, "stderr"), "w+")
            p = subprocess.Popen([lpvd] + pod.args, env=pod.index_env(i), stderr=log)
            deadline = time.time() + 60
            first = False
            while p.poll() is None and time.time() < deadline and not first:
                if os.path.exists(pod.manifest(i)):
                    with open(pod.manifest(i)) as f:
                        first = f.read().endswith("\n")
                time.sleep(0.01)
            p.send_signal(signal.SIGTERM)
            try:
                rc = p.wait(timeout=120)
            except subprocess.TimeoutExpired:
                p.kill()
                rc = p.wait()
            log.seek(0)
            text = log.read().strip()
            log.close()
            done = [e.get("id") for e in pod.lines([pod.manifest(i)])]
            check(first, f"{where}: index {i}: no manifest line before SIGTERM: {text[-2000:]}")
            check(rc == 3, f"{where}: index {i}: exited {rc} on SIGTERM with items left, not 3: {text[-2000:]}")
            check(policy_action(rules, c.get("name"), rc) == "Ignore",
                  f"{where}: podFailurePolicy does not ignore {rc}, the status lpvd batch exits with on SIGTERM")
            check(1 <= len(done) < len(mine), f"{where}: index {i}: {len(done)} of {len(mine)} items recorded "
                                              f"after SIGTERM; expected some, not all")
            rc, text = pod.run(i)
            check(rc == 0, f"{where}: index {i} run again after SIGTERM exited {rc}, not 0: {text[-2000:]}")
            lines = pod.lines([pod.manifest(i)])
            got = sorted(e.get("id") for e in lines)
            check(got == sorted(mine), f"{where}: index {i} after resuming holds {got}, not each of {mine} once")
            check(all(e.get("status") == "ok" for e in lines), f"{where}: index {i}: an item failed: {lines}")
            print(f"test_k8s_manifests: {where}: {pod.shards} indexes of a 2-item job; index {i} of a "
                  f"{4 * pod.shards}-item job: SIGTERM after its first item, {len(done)} of {len(mine)} items "
                  f"recorded, exit 3; run again: exit {rc}, {len(got)} items")


def check_serve(docs, entry, lpvctl):
    services = {d["metadata"]["name"]: d for _, d in docs if d.get("kind") == "Service"}
    serve = []
    for where, d in docs:
        if d.get("kind") not in ("Deployment", "StatefulSet"):
            continue
        for c in pod_spec(d).get("containers") or []:
            argv = effective_argv(c, entry)
            if argv and len(argv) >= 2 and argv[1] == "serve":
                serve.append((where, d, c, argv))
    if not check(serve, "docker/k8s: no Deployment or StatefulSet runs `lpvd serve`"):
        return []
    for where, d, c, argv in serve:
        check(argv[0] == entry, f"{where}: runs {argv[0]}, not the image's lpvd ({entry})")
        spec = pod_spec(d)

        def flag(name):
            return argv[argv.index(name) + 1] if name in argv[:-1] else None

        listen = flag("--listen")
        token = flag("--token-file")
        if check(listen and ":" in listen, f"{where}: lpvd serve without --listen HOST:PORT"):
            port = int(listen.rsplit(":", 1)[1])
            ports = [p.get("containerPort") for p in c.get("ports") or []]
            check(port in ports, f"{where}: --listen port {port} is not a containerPort {ports}")
        check(token, f"{where}: --listen on a pod address needs --token-file")
        if token:
            mounts = {m.get("name"): m.get("mountPath") for m in c.get("volumeMounts") or []}
            secret_vols = [v.get("name") for v in spec.get("volumes") or [] if "secret" in v]
            check(any(mounts.get(v) and token.startswith(mounts[v].rstrip("/") + "/") for v in secret_vols),
                  f"{where}: --token-file {token} is not in a mounted Secret")
        for kind in ("readinessProbe", "livenessProbe"):
            probe = c.get(kind)
            if not check(isinstance(probe, dict) and probe, f"{where}: no {kind}"):
                continue
            if "exec" in probe:
                text = " ".join(probe["exec"].get("command") or [])
                check(lpvctl in text, f"{where}: {kind} does not run {lpvctl}")
                if listen:
                    check(f"127.0.0.1:{listen.rsplit(':', 1)[1]}" in text,
                          f"{where}: {kind} does not connect to the --listen port")
                if token:
                    check(f"--token-file {token}" in text, f"{where}: {kind} does not send the token file {token}")
            else:
                check("tcpSocket" in probe or "grpc" in probe or "httpGet" in probe, f"{where}: {kind} has no handler")
        grace = spec.get("terminationGracePeriodSeconds")
        check(isinstance(grace, int) and grace >= 12,
              f"{where}: terminationGracePeriodSeconds {grace!r} shorter than the drain (tick + 2 s + 5 s)")
        if d["kind"] == "StatefulSet":
            svc = services.get(d["spec"].get("serviceName"))
            if check(svc, f"{where}: serviceName {d['spec'].get('serviceName')!r} is no Service here"):
                check(svc["spec"].get("clusterIP") == "None",
                      f"{where}: its Service must be headless (clusterIP: None) for per-replica names")
                labels = (d["spec"]["template"].get("metadata") or {}).get("labels") or {}
                check(all(labels.get(k) == v for k, v in (svc["spec"].get("selector") or {}).items()),
                      f"{where}: the Service's selector does not select its pods")
    return serve


# --- the daemon, live -------------------------------------------------------

def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def check_serve_live(serve, build_dir, lpvd, lpvctl_bin):
    for where, d, c, argv in serve:
        if not all("exec" in (c.get(k) or {}) for k in ("readinessProbe", "livenessProbe")) \
                or "--listen" not in argv or "--token-file" not in argv:
            continue  # check_serve said what is missing
        with tempfile.TemporaryDirectory() as tmp:
            listen = argv[argv.index("--listen") + 1]
            token = argv[argv.index("--token-file") + 1]
            port = free_port()
            tok = os.path.join(tmp, "token")
            with open(tok, "w") as f:
                f.write("k8s-manifest-test-token")
            bad = os.path.join(tmp, "bad")
            with open(bad, "w") as f:
                f.write("wrong")
            roots = os.path.join(tmp, "scenes")
            os.mkdir(roots)
            swap = {listen: f"127.0.0.1:{port}", token: tok}
            if "--scene-root" in argv:
                swap[argv[argv.index("--scene-root") + 1]] = roots
            args = [swap.get(a, a) for a in argv[1:]]
            # one session fills the daemon: a full replica is still ready
            if "--max-clients" in args:
                args[args.index("--max-clients") + 1] = "1"
            else:
                args += ["--max-clients", "1"]

            def probe(kind, token_file):
                cmd = []
                for a in c[kind]["exec"]["command"]:
                    a = a.replace(os.path.join(build_dir, "clients", "lpvctl", "lpvctl"), lpvctl_bin)
                    a = a.replace(f"127.0.0.1:{listen.rsplit(':', 1)[1]}", f"127.0.0.1:{port}")
                    cmd.append(a.replace(token, token_file))
                r = subprocess.run(cmd, capture_output=True, text=True, timeout=30)
                return r.returncode, (r.stdout + r.stderr).strip()

            err = open(os.path.join(tmp, "stderr"), "w+")
            p = subprocess.Popen([lpvd] + args, stderr=err)
            try:
                deadline = time.time() + 60
                while time.time() < deadline and p.poll() is None:
                    err.seek(0)
                    if "listening on" in err.read():
                        break
                    time.sleep(0.1)
                err.seek(0)
                log = err.read()
                if not check(p.poll() is None and "listening on" in log,
                             f"{where}: lpvd serve with the manifest's args did not start: {log.strip()}"):
                    continue
                for kind in ("readinessProbe", "livenessProbe"):
                    rc, out = probe(kind, tok)
                    check(rc == 0, f"{where}: {kind} fails against a healthy daemon: {out}")
                holder = subprocess.Popen([lpvctl_bin, "--address", f"127.0.0.1:{port}", "--token-file", tok, "shell"],
                                          stdin=subprocess.PIPE, stdout=subprocess.DEVNULL)
                try:
                    time.sleep(1)
                    check(holder.poll() is None, f"{where}: could not open the one session of --max-clients 1")
                    for kind in ("readinessProbe", "livenessProbe"):
                        rc, out = probe(kind, tok)
                        check(rc == 0, f"{where}: {kind} fails against a full daemon (HELLO gets LIMIT): {out}")
                finally:
                    holder.stdin.close()
                    holder.wait(timeout=30)
                rc, out = probe("readinessProbe", bad)
                check(rc != 0, f"{where}: readinessProbe passes with a wrong token")
                rc, out = probe("livenessProbe", bad)
                check(rc == 0, f"{where}: livenessProbe fails on UNAUTHORIZED (the daemon did answer): {out}")
                p.send_signal(signal.SIGTERM)
                check(p.wait(timeout=30) == 0, f"{where}: lpvd serve did not exit 0 on SIGTERM")
                for kind in ("readinessProbe", "livenessProbe"):
                    rc, out = probe(kind, tok)
                    check(rc != 0, f"{where}: {kind} passes with the daemon stopped")
            finally:
                if p.poll() is None:
                    p.kill()
                    p.wait()
                err.close()


def main():
    name = image_name()
    entry, build_dir = dockerfile()
    lpvctl = lpvctl_path(build_dir) if build_dir else None
    docs = load_manifests()
    if name:
        check_images(docs, name)
    serve = []
    batch = []
    if entry:
        batch = check_jobs(docs, entry)
        serve = check_serve(docs, entry, lpvctl)
    lpvd_bin = os.environ.get("LPVD_BINARY")
    lpvctl_bin = os.environ.get("LPVCTL_BINARY")
    if lpvd_bin and os.path.exists(lpvd_bin):
        check_batch_live(batch, lpvd_bin)
    elif batch:
        print("test_k8s_manifests: LPVD_BINARY not set: the Jobs' lpvd batch was not run")
    if serve and lpvd_bin and lpvctl_bin and os.path.exists(lpvd_bin) and os.path.exists(lpvctl_bin):
        check_serve_live(serve, build_dir, lpvd_bin, lpvctl_bin)
    elif serve:
        print("test_k8s_manifests: LPVD_BINARY / LPVCTL_BINARY not set: the probes were not run against a daemon")
    for f in failures:
        print("FAIL:", f)
    print(f"test_k8s_manifests: {len(docs)} documents in docker/k8s, image {name}, "
          f"{'FAILED (%d)' % len(failures) if failures else 'all checks passed'}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
