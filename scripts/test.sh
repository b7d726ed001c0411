#!/bin/sh
# Every test on a fresh Debian 12 machine: install, build, run the whole
# suite (GL tests on Mesa's llvmpipe when there is no GPU; the daemon's
# conformance and reliability suites against fresh daemons), fuzz the wire
# protocol for a bounded minute and the glTF loader and its images for 30 s
# each, then build again with AddressSanitizer +
# UndefinedBehaviorSanitizer and run the whole suite again. Warnings are
# errors in every build.
set -eu
cd "$(dirname "$0")/.."
sh scripts/install-deps.sh
jobs="$(nproc)"

cmake -S . -B build -DCMAKE_BUILD_TYPE=RelWithDebInfo
cmake --build build -j "$jobs"
ctest --test-dir build --output-on-failure -j "$jobs"

# Fuzz the wire protocol (frame parser, bodies, field getters, zstd) for a
# bounded minute with libFuzzer + ASan + UBSan (clang); new inputs go to
# build-fuzz/corpus, the seeds in tests/fuzz/corpus are only read. --fresh:
# a build-fuzz configured with other compilers would otherwise drop these
# -D options when CMake resets its cache for the compiler change.
cmake --fresh -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang \
  -DCMAKE_CXX_COMPILER=clang++ -DLPVD_FUZZ=ON
cmake --build build-fuzz --target fuzz_frame fuzz_gltf fuzz_image -j "$jobs"
mkdir -p build-fuzz/corpus build-fuzz/corpus-gltf build-fuzz/corpus-image
./build-fuzz/fuzz/fuzz_frame -max_total_time=60 -rss_limit_mb=2048 -max_len=65536 \
  -print_final_stats=1 build-fuzz/corpus tests/fuzz/corpus
# The glTF loader and its image path (bytes to the scene model through the
# daemon's entry), 30 s each; scripts/fuzz-long.sh runs them for hours.
./build-fuzz/fuzz/fuzz_gltf -max_total_time=30 -rss_limit_mb=2048 -max_len=1048576 -timeout=30 \
  -print_final_stats=1 build-fuzz/corpus-gltf tests/fuzz/corpus_gltf
./build-fuzz/fuzz/fuzz_image -max_total_time=30 -rss_limit_mb=2048 -malloc_limit_mb=4096 -max_len=1048576 -timeout=30 \
  -print_final_stats=1 build-fuzz/corpus-image tests/fuzz/corpus_image

cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DLPVD_SANITIZE=ON
cmake --build build-asan -j "$jobs"
# Mesa and LLVM keep some allocations for the life of the process; the
# suppressions name only their libraries, never lpvd's code.
# intercept_tls_get_addr=0: GCC 12's LeakSanitizer records each dynamic TLS
# block from __tls_get_addr and, when a block's address is 16 past a page
# boundary, takes it for glibc <= 2.18 and reads a "header" before it that
# modern glibc does not write; the garbage range ("DTLS 42 at
# 0x2a68-0x1800003b6a") then faults its scan ("Tracer caught signal 11",
# exit -6), in about one run of lpvd batch in twenty-five under load. Without
# the interception LeakSanitizer still reaches every dynamic TLS block, from
# the thread's DTV, which glibc allocates with malloc.
ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:intercept_tls_get_addr=0" \
UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
LSAN_OPTIONS="suppressions=$(pwd)/tests/lsan.supp:print_suppressions=0" \
  ctest --test-dir build-asan --output-on-failure -j "$jobs"
