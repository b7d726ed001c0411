#!/bin/sh
# Installs the Debian 12 packages lpvd needs. Run as root, or as a user with
# sudo. Safe to run repeatedly.
#
#   sh scripts/install-deps.sh             everything: build, run, test and benchmark
#   sh scripts/install-deps.sh --runtime   what the built lpvd and lpvctl need to run (docker/Dockerfile's image)
#   sh scripts/install-deps.sh --build     what building them needs
#   sh scripts/install-deps.sh --print GROUP   prints a group's packages (runtime, build, test) and installs nothing
set -eu

# Running lpvd and lpvctl: the shared libraries they link (the test
# runtime_deps_cover_binaries checks the list against `ldd`), and what lpvd
# opens at run time: Mesa's EGL and drivers (llvmpipe), OSMesa the last
# fallback (docs/gl-backends.md).
RUNTIME="
  libegl1 libegl-mesa0 libgl1-mesa-dri libosmesa6
  libopenimageio2.4 libembree3-3 libjansson4 libuv1 libzstd1 libxxhash0 libmeshoptimizer2d libtinygltf2d libstb0
  libcglm0
"
# Building them (draco is linked statically; cglm's functions are mostly
# inlined, but a build that does not inline them links libcglm0).
# khronos-api: the OpenGL registry (gl.xml) that cmake/gen_gl_api.py turns
# into gpu/gl_api.h at build time (docs/gl-backends.md); python3 runs it.
# libcmocka-dev: the tests' framework, which the build configures with them.
BUILD="
  build-essential cmake pkg-config python3
  libegl-dev libgl-dev mesa-common-dev libegl-mesa0 libgl1-mesa-dri libosmesa6-dev
  khronos-api
  libtinygltf-dev nlohmann-json3-dev libstb-dev libglm-dev libdraco-dev libmeshoptimizer-dev
  libopenimageio-dev
  libcglm-dev libuv1-dev libzstd-dev zstd libxxhash-dev libjansson-dev libembree-dev
  libcmocka-dev
"
# Testing and benchmarking (tests/README.md).
# clang, libclang-rt-14-dev: the fuzzers (libFuzzer) scripts/test.sh runs.
# python3-jsonschema: tests/batch/batch_cli.py checks job files against
# docs/batch.schema.json.
# python3-yaml: PyYAML, with which tests/test_k8s_manifests.py parses the
# Kubernetes manifests of docker/k8s/.
# gnuplot-nox: the accuracy sweep's plots.
# assimp-testmodels: glTF 2.0 sample models (/usr/share/assimp/models) that
# tests/test_realscene.c, tests/test_gltf_corpus.c and the accuracy sweep
# render as scenes the project did not write.
# chromium: the batch report test (tests/report_browser.py) opens report.html
# in it, headless, to check the page's thumbnails load and its script logs no
# error; the test fails without it.
TEST="
  clang libclang-rt-14-dev
  python3-jsonschema python3-yaml gnuplot-nox
  assimp-testmodels
  chromium
"

case "${1:-}" in
"") PACKAGES="$RUNTIME $BUILD $TEST" ;;
--runtime) PACKAGES="$RUNTIME" ;;
--build) PACKAGES="$BUILD" ;;
--print)
  case "${2:-}" in
  runtime) echo $RUNTIME ;;
  build) echo $BUILD ;;
  test) echo $TEST ;;
  *) echo "install-deps: --print runtime, build or test" >&2; exit 2 ;;
  esac
  exit 0 ;;
*) echo "install-deps: unknown option '$1' (--runtime, --build, --print GROUP, or nothing for everything)" >&2; exit 2 ;;
esac

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
