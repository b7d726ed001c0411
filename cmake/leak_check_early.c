/*
 * leak_check_early.c - linked into every executable of the sanitizer build
 * (LPVD_SANITIZE, see CMakeLists.txt); never into a release build.
 *
 * Why: OpenImageIO pulls in OpenVDB, which pulls in log4cplus 2.0, whose
 * static thread pool starts four workers when the library loads. At exit its
 * static destructor tells them to stop and each worker detaches itself and
 * exits on its own time. LeakSanitizer's end-of-process check runs after all
 * library destructors, so on a loaded machine it can stop the world while one
 * of those workers is halfway out; its tracer then faults ("Tracer caught
 * signal 11", LeakSanitizer fatal error) and a test whose checks all passed
 * fails. That happened in CI (test_octree_gpu, 2026-11-25).
 *
 * This file registers the leak check with atexit from a constructor of the
 * executable. Library constructors run first, so this handler runs before the
 * libraries' static destructors, while the workers still wait idle on their
 * condition variable. The check is the same full check (__lsan_do_leak_check
 * terminates with the leak report when there are leaks, and the end-of-process
 * check then does not run again); memory the later destructors free is still
 * reachable from their globals at this point, so it is not reported either.
 */
#include <sanitizer/lsan_interface.h>
#include <stdlib.h>

static void leak_check_now(void)
{
    __lsan_do_leak_check();
}

__attribute__((constructor)) static void register_leak_check(void)
{
    atexit(leak_check_now);
}
