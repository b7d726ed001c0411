#!/bin/sh
# Installs every Debian 12 package lpvd needs to build, run, test and benchmark.
# Run as root, or as a user with sudo. Safe to run repeatedly.
set -eu

PACKAGES="
  build-essential cmake pkg-config clang libclang-rt-14-dev
  libegl-dev libgl-dev mesa-common-dev libegl-mesa0 libgl1-mesa-dri libosmesa6-dev
  khronos-api
  libtinygltf-dev nlohmann-json3-dev libstb-dev libglm-dev libdraco-dev libmeshoptimizer-dev
  libopenimageio-dev
  libcglm-dev libuv1-dev libzstd-dev zstd libjansson-dev libembree-dev
  libcmocka-dev
  python3 python3-jsonschema python3-yaml gnuplot-nox
  assimp-testmodels
  chromium
"
# khronos-api: the OpenGL registry (gl.xml) that cmake/gen_gl_api.py turns
# into gpu/gl_api.h at build time (docs/gl-backends.md).
# python3-jsonschema: tests/batch/batch_cli.py checks job files against
# docs/batch.schema.json.
# python3-yaml: PyYAML, with which tests/test_k8s_manifests.py parses the
# Kubernetes manifests of docker/k8s/.
# assimp-testmodels: glTF 2.0 sample models (/usr/share/assimp/models) that
# tests/test_realscene.c and the accuracy sweep render as scenes the project
# did not write.
# chromium: the batch report test (tests/report_browser.py) opens report.html
# in it, headless, to check the page's thumbnails load and its script logs no
# error; the test fails without it.

if [ "$(id -u)" -eq 0 ]; then
  SUDO=""
elif command -v sudo >/dev/null 2>&1; then
  SUDO="sudo"
else
  echo "install-deps: run as root or install sudo" >&2
  exit 1
fi

missing=""
for p in $PACKAGES; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done

if [ -n "$missing" ]; then
  echo "install-deps: installing:$missing"
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get update -q
  # shellcheck disable=SC2086
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends $missing
else
  echo "install-deps: all packages present"
fi
