#!/usr/bin/env python3
"""lpvd_replica.py - which `lpvd serve` replica the clients of a scene use.

The reference implementation of the client-side rule of docs/deploy.md,
"Scene-affine routing", for the StatefulSet of serve-deployment.yaml. Every
client of a scene must compute the same replica, so that their sessions land
in one daemon and share its scene and worlds. Standard library only; copy
replica_index() into a client, or run this file:

    $ python3 docker/k8s/lpvd_replica.py --replicas 3 cornell-box.glb
    lpvd-1.lpvd.default.svc.cluster.local:7070
    $ python3 docker/k8s/lpvd_replica.py --replicas 3 --index --glb scenes/blinds.glb
    2

The rule (rendezvous, or highest-random-weight, hashing):

    key       the scene id: the SCENE_LOAD "path" exactly as the client sends
              it; "sha256:" + the lowercase hex SHA-256 of the .glb bytes for
              a scene sent as an attachment; "" for a session that loads no
              scene (the daemon's default scene)
    weight(i) the first 8 bytes, read as a big-endian unsigned integer, of
              SHA-256(UTF-8 key + "\\n" + i in decimal ASCII)
    replica   the i in 0 .. N-1 (N = the StatefulSet's replicas) with the
              largest weight; on a tie the smaller i

Changing N from N to N + 1 moves only the scenes whose new largest weight is
replica N (about 1 in N + 1); removing the last replica moves only its own.
"""
import argparse
import hashlib
import sys


def scene_key_for_path(path):
    """The key of a scene loaded by path (SCENE_LOAD "path")."""
    return path


def scene_key_for_glb(data):
    """The key of a scene sent as the bytes of a .glb (SCENE_LOAD attachment)."""
    return "sha256:" + hashlib.sha256(data).hexdigest()


def weight(key, i):
    digest = hashlib.sha256(key.encode("utf-8") + b"\n" + str(i).encode("ascii")).digest()
    return int.from_bytes(digest[:8], "big")


def replica_index(key, replicas):
    """The replica (0 .. replicas-1) the clients of scene `key` connect to."""
    if replicas < 1:
        raise ValueError("replicas must be at least 1")
    best = 0
    best_w = weight(key, 0)
    for i in range(1, replicas):
        w = weight(key, i)
        if w > best_w:
            best, best_w = i, w
    return best


def replica_address(index, statefulset="lpvd", service="lpvd", namespace="default",
                    cluster_domain="cluster.local", port=7070):
    """The lpvctl / lpvc address of replica `index` (the headless Service's pod name)."""
    return f"{statefulset}-{index}.{service}.{namespace}.svc.{cluster_domain}:{port}"


def main(argv):
    ap = argparse.ArgumentParser(description="Print the lpvd serve replica of each scene (docs/deploy.md).")
    ap.add_argument("--replicas", type=int, required=True, help="the StatefulSet's spec.replicas")
    ap.add_argument("--namespace", default="default")
    ap.add_argument("--statefulset", default="lpvd")
    ap.add_argument("--service", default="lpvd")
    ap.add_argument("--cluster-domain", default="cluster.local")
    ap.add_argument("--port", type=int, default=7070)
    ap.add_argument("--glb", action="append", default=[], metavar="FILE",
                    help="a scene sent as an attachment: its key is the SHA-256 of the file")
    ap.add_argument("--index", action="store_true", help="print the replica index only")
    ap.add_argument("paths", nargs="*", help="scene ids of scenes loaded by path, as sent in SCENE_LOAD")
    a = ap.parse_args(argv)
    if a.replicas < 1:
        ap.error("--replicas must be at least 1")
    keys = [scene_key_for_path(p) for p in a.paths]
    for f in a.glb:
        with open(f, "rb") as fh:
            keys.append(scene_key_for_glb(fh.read()))
    if not keys:
        ap.error("give at least one scene path or --glb FILE")
    for k in keys:
        i = replica_index(k, a.replicas)
        print(i if a.index else replica_address(i, a.statefulset, a.service, a.namespace, a.cluster_domain, a.port))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
