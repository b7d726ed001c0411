/* test_util.h - small helpers shared by the tests (paths, temp folders). */
#ifndef LPV_TEST_UTIL_H
#define LPV_TEST_UTIL_H

#include <stddef.h>
#include <stdint.h>

/* ../shared next to the checkout (LPVD_SHARED_DIR), or NULL when absent:
 * tests that use it skip cleanly without it. */
const char *lpvt_shared_dir(void);

/* The source tree (LPVD_SOURCE_DIR). */
const char *lpvt_source_dir(void);

/* A fresh temporary folder for this test process ($TMPDIR or /tmp), removed
 * with everything in it when the process that made it exits normally (a
 * crashed test leaves it to look at). Never NULL; aborts on failure. */
const char *lpvt_tmpdir(void);

/* Writes size bytes to dir/name and returns the full path in a static buffer
 * rotated over 8 slots. Aborts on failure. */
const char *lpvt_write_file(const char *dir, const char *name, const void *data, size_t size);

/* printf into one of four rotating static buffers (64 KiB each), then every
 * ' becomes ": JSON in C strings without escapes. Fails the test on overflow. */
const char *lpvt_json(const char *fmt, ...);

/* For GL tests: a context (auto backend) and an engine on it. Returns 0, or
 * -1 after printing why (cmocka then fails the group set-up). */
struct lpv_gl_context;
struct lpv_engine;
int lpvt_gl_open(struct lpv_gl_context **ctx, struct lpv_engine **engine);
void lpvt_gl_close(struct lpv_gl_context *ctx, struct lpv_engine *engine);

/* cmocka group fixtures for files whose tests share one context and engine:
 * cmocka_run_group_tests(tests, lpvt_gl_setup, lpvt_gl_teardown), then use
 * lpvt_engine. */
extern struct lpv_engine *lpvt_engine;
int lpvt_gl_setup(void **state);
/* A uniform number in [lo, hi) from the xorshift64 generator *state (a
 * test's own, so each test's data is reproducible on its own). */
double lpvt_rand(uint64_t *state, double lo, double hi);

/* The shared engine's full frame at width x height (the view set before),
 * calloc'd; fails the test with the engine's message on error. */
float *lpvt_render(int width, int height);
int lpvt_gl_teardown(void **state);

/* 1 if the shared engine's last stats hold a stage of that name (its calls
 * in *calls, its gpu_ms in *ms, either may be NULL), else 0. */
int lpvt_stage(const char *name, unsigned *calls, double *ms);

/* The point where pixel (x, y)'s primary ray (lpv_ref_pixel_ray) meets the
 * floor plane y = 0: 1 and p, or 0 when the ray does not go down. */
struct lpv_view;
int lpvt_floor_point(const struct lpv_view *v, int x, int y, float p[3]);

/* Mean radiance (rgb) over the (2 radius + 1)^2 pixels of a width x height
 * RGBA float frame where world point p lands in view v; fails the test when
 * the patch leaves the frame or a pixel saw no geometry. */
struct lpv_view;
void lpvt_patch(const struct lpv_view *v, const float *rgba, int width, int height, const float p[3], int radius,
                double out[3]);

#endif
