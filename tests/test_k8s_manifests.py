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
  - each Indexed Job runs `lpvd batch` with LPVD_SHARDS = spec.completions,
    its failure policy ignores the exit status its SIGTERM wrapper uses, and
    a GPU Job asks for the NVIDIA graphics capability (EGL);
  - the daemon's workload runs `lpvd serve`, has readiness and liveness
    probes, and its token, port and headless Service agree.

Behaviour, always (needs only /bin/sh): each Job's SIGTERM wrapper, run around
a fake lpvd, passes exit statuses 0, 1 and 2 through, and on SIGTERM passes
the signal on, waits for the item in flight and exits 143.

Behaviour, when LPVD_BINARY and LPVCTL_BINARY are set (ctest sets them):
`lpvd serve` starts with the manifest's own args and the probes' commands
pass against it, the readiness probe fails with a wrong token while liveness
holds, and both fail once it has stopped.

Needs PyYAML (Debian: python3-yaml, in scripts/install-deps.sh). Exit 0 when
every check passes, 1 otherwise (each failure printed).
"""
import glob
import json
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


def wrapper_script(c):
    """The script of `command: [/bin/sh, -c, SCRIPT, NAME]`, else None."""
    cmd = c.get("command") or []
    if len(cmd) >= 3 and cmd[0] in ("/bin/sh", "sh", "/bin/bash", "bash") and cmd[1] == "-c":
        return cmd[2]
    return None


def effective_argv(c, entry):
    """What the container runs as lpvd's argv: ENTRYPOINT + args, command + args,
    or a sh -c wrapper's "$@" (its args)."""
    cmd = c.get("command")
    args = list(c.get("args") or [])
    if not cmd:
        return [entry] + args
    script = wrapper_script(c)
    if script is not None:
        return args if '"$@"' in script else None
    return list(cmd) + args


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


def check_jobs(docs, entry):
    jobs = [(w, d) for w, d in docs if d.get("kind") == "Job"]
    indexed = [(w, d) for w, d in jobs if (d.get("spec") or {}).get("completionMode") == "Indexed"]
    check(indexed, "docker/k8s: no Indexed Job (completionMode: Indexed)")
    scripts = {}
    policies = {}
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
        grace = tmpl.get("terminationGracePeriodSeconds")
        check(isinstance(grace, int) and grace >= 60,
              f"{where}: terminationGracePeriodSeconds {grace!r}: must let the item in flight finish (>= 60)")
        batch = []
        for c in tmpl.get("containers") or []:
            argv = effective_argv(c, entry)
            if argv and len(argv) >= 2 and argv[1] == "batch":
                batch.append((c, argv))
        if not check(len(batch) == 1, f"{where}: expected one container running `lpvd batch`, found {len(batch)}"):
            continue
        c, argv = batch[0]
        check(argv[0] == entry, f"{where}: runs {argv[0]}, not the image's lpvd ({entry})")
        shards = env_value(c, "LPVD_SHARDS")
        check(shards is not None and str(shards) == str(completions),
              f"{where}: LPVD_SHARDS {shards!r} != spec.completions {completions!r}")
        check("--shard" not in argv, f"{where}: --shard on the command line overrides JOB_COMPLETION_INDEX")
        check("--out" in argv, f"{where}: lpvd batch without --out")
        rules = (spec.get("podFailurePolicy") or {}).get("rules") or []
        for r in rules:
            cn = (r.get("onExitCodes") or {}).get("containerName")
            check(cn is None or cn == c.get("name"),
                  f"{where}: podFailurePolicy names container {cn!r}, the batch container is {c.get('name')!r}")
        script = wrapper_script(c)
        if script is not None:
            scripts[where] = script
            for code in sorted(set(re.findall(r"\bexit (\d+)\b", script))):
                ignored = any(r.get("action") == "Ignore" and int(code) in ((r.get("onExitCodes") or {}).get("values") or [])
                              for r in rules)
                check(ignored, f"{where}: the wrapper exits {code} on SIGTERM but podFailurePolicy does not Ignore it")
        policies[where] = rules
        limits = (c.get("resources") or {}).get("limits") or {}
        if "nvidia.com/gpu" in limits:
            caps = env_value(c, "NVIDIA_DRIVER_CAPABILITIES") or ""
            check("graphics" in caps.split(",") or caps == "all",
                  f"{where}: a GPU Job without graphics in NVIDIA_DRIVER_CAPABILITIES gets no NVIDIA EGL")
        check_wrapper(where, c, argv)
    check(len(set(scripts.values())) <= 1, f"the Jobs' SIGTERM wrappers differ: {sorted(scripts)}")
    check(len({json.dumps(p, sort_keys=True) for p in policies.values()}) <= 1,
          f"the Jobs' podFailurePolicy rules differ: {sorted(policies)}")


FAKE_LPVD = """#!/bin/sh
# a fake `lpvd batch`: items of 0.1 s; on SIGTERM it finishes the item in
# flight and exits 0, as the real one does when nothing failed
echo "argv $*" >> "$FAKE_LOG"
trap 'echo term >> "$FAKE_LOG"; sleep 0.3; echo item-finished >> "$FAKE_LOG"; exit 0' TERM
i=0
while [ "$i" -lt "$FAKE_ITEMS" ]; do sleep 0.1; i=$((i + 1)); done
exit "$FAKE_RC"
"""


def check_wrapper(where, c, argv):
    """Runs the container's command around a fake lpvd (no Kubernetes needed)."""
    if wrapper_script(c) is None:
        return
    with tempfile.TemporaryDirectory() as tmp:
        fake = os.path.join(tmp, "lpvd")
        with open(fake, "w") as f:
            f.write(FAKE_LPVD)
        os.chmod(fake, 0o755)
        log = os.path.join(tmp, "log")
        cmd = list(c["command"]) + [fake] + argv[1:]
        env = dict(os.environ, FAKE_LOG=log, FAKE_ITEMS="2")
        for rc in (0, 1, 2):
            env["FAKE_RC"] = str(rc)
            got = subprocess.run(cmd, env=env, timeout=30).returncode
            check(got == rc, f"{where}: the wrapper turned lpvd's exit status {rc} into {got}")
        with open(log) as f:
            check(f.readline().strip() == "argv " + " ".join(argv[1:]),
                  f"{where}: the wrapper did not pass lpvd its arguments")
        os.unlink(log)
        env.update(FAKE_ITEMS="300", FAKE_RC="0")
        p = subprocess.Popen(cmd, env=env)
        deadline = time.time() + 10
        while not (os.path.exists(log) and open(log).read()) and time.time() < deadline:
            time.sleep(0.05)
        time.sleep(0.2)  # let the wrapper reach its wait
        p.send_signal(signal.SIGTERM)
        try:
            got = p.wait(timeout=10)
        except subprocess.TimeoutExpired:
            p.kill()
            got = None
        with open(log) as f:
            lines = f.read().split()
        check(got == 143, f"{where}: on SIGTERM the wrapper exited {got}, not 143 (a 0 would complete the index)")
        check("term" in lines, f"{where}: the wrapper did not pass SIGTERM on to lpvd")
        check("item-finished" in lines, f"{where}: the wrapper exited before lpvd finished its item")


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
    if entry:
        check_jobs(docs, entry)
        serve = check_serve(docs, entry, lpvctl)
    lpvd_bin = os.environ.get("LPVD_BINARY")
    lpvctl_bin = os.environ.get("LPVCTL_BINARY")
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
