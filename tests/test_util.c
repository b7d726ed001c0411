/* test_util.c - see test_util.h. */
#define _XOPEN_SOURCE 700 /* nftw */
#include "test_util.h"

#include "context.h"
#include "engine.h"
#include "pt.h"
#include "view.h"

#include <ftw.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

const char *lpvt_shared_dir(void)
{
    const char *d = getenv("LPVD_SHARED_DIR");
    struct stat st;
    if (!d || stat(d, &st) != 0 || !S_ISDIR(st.st_mode))
        return NULL;
    return d;
}

const char *lpvt_source_dir(void)
{
    const char *d = getenv("LPVD_SOURCE_DIR");
    return d ? d : ".";
}

static char tmpdir_path[256];
static pid_t tmpdir_owner;

static int remove_entry(const char *path, const struct stat *st, int flag, struct FTW *ftw)
{
    (void)st, (void)flag, (void)ftw;
    if (remove(path) != 0)
        perror(path);
    return 0;
}

/* Every test program left its directory behind (hundreds in /tmp after a
 * few runs of the suite): the process that made it removes it at exit; a
 * forked child that calls exit() does not, its parent may still use it. */
static void remove_tmpdir(void)
{
    if (tmpdir_path[0] && getpid() == tmpdir_owner)
        nftw(tmpdir_path, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
}

const char *lpvt_tmpdir(void)
{
    if (!tmpdir_path[0]) {
        const char *base = getenv("TMPDIR");
        snprintf(tmpdir_path, sizeof tmpdir_path, "%s/lpvd-test-XXXXXX", base ? base : "/tmp");
        if (!mkdtemp(tmpdir_path)) {
            perror("mkdtemp");
            abort();
        }
        tmpdir_owner = getpid();
        atexit(remove_tmpdir);
    }
    return tmpdir_path;
}

const char *lpvt_write_file(const char *dir, const char *name, const void *data, size_t size)
{
    static char slots[8][512];
    static int next;
    char *p = slots[next++ & 7];
    snprintf(p, 512, "%s/%s", dir, name);
    FILE *f = fopen(p, "wb");
    if (!f || (size && fwrite(data, 1, size, f) != size)) {
        perror(p);
        abort();
    }
    fclose(f);
    return p;
}

int lpvt_gl_open(lpv_gl_context **ctx, lpv_engine **engine)
{
    char err[1024];
    *engine = NULL;
    *ctx = lpv_gl_context_create(&(lpv_gl_context_desc){0}, err, sizeof err);
    if (!*ctx) {
        fprintf(stderr, "no GL context: %s\n", err);
        return -1;
    }
    *engine = lpv_engine_create(err, sizeof err);
    if (!*engine) {
        fprintf(stderr, "no engine: %s\n", err);
        return -1;
    }
    return 0;
}

void lpvt_gl_close(lpv_gl_context *ctx, lpv_engine *engine)
{
    lpv_engine_destroy(engine);
    lpv_gl_context_destroy(ctx);
}

static lpv_gl_context *lpvt_ctx;
lpv_engine *lpvt_engine;

int lpvt_gl_setup(void **state)
{
    (void)state;
    return lpvt_gl_open(&lpvt_ctx, &lpvt_engine);
}

int lpvt_gl_teardown(void **state)
{
    (void)state;
    lpvt_gl_close(lpvt_ctx, lpvt_engine);
    lpvt_ctx = NULL;
    lpvt_engine = NULL;
    return 0;
}

const char *lpvt_json(const char *fmt, ...)
{
    static char slots[4][65536];
    static int next;
    char *p = slots[next++ & 3];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(p, sizeof slots[0], fmt, ap);
    va_end(ap);
    assert_true(n > 0 && (size_t)n < sizeof slots[0]);
    for (char *c = p; *c; c++)
        if (*c == '\'')
            *c = '"';
    return p;
}

int lpvt_floor_point(const lpv_view *v, int x, int y, float p[3])
{
    float org[3], dir[3], tmin, tmax;
    lpv_ref_pixel_ray(v, x, y, org, dir, &tmin, &tmax);
    if (!(dir[1] < 0.0f))
        return 0;
    const float t = -org[1] / dir[1];
    p[0] = org[0] + t * dir[0], p[1] = 0.0f, p[2] = org[2] + t * dir[2];
    return 1;
}

void lpvt_patch(const lpv_view *v, const float *rgba, int width, int height, const float p[3], int radius,
                double out[3])
{
    float px, py;
    assert_int_equal(lpv_view_project(v, p, &px, &py), 0);
    int cx = (int)px, cy = (int)py, n = 0;
    out[0] = out[1] = out[2] = 0.0;
    for (int y = cy - radius; y <= cy + radius; ++y)
        for (int x = cx - radius; x <= cx + radius; ++x) {
            assert_true(x >= 0 && x < width && y >= 0 && y < height);
            const float *q = &rgba[((size_t)y * (size_t)width + (size_t)x) * 4];
            assert_true(q[3] > 0.5f); /* geometry was hit */
            for (int c = 0; c < 3; ++c)
                out[c] += q[c];
            ++n;
        }
    for (int c = 0; c < 3; ++c)
        out[c] /= n;
}

float *lpvt_render(int width, int height)
{
    char err[512] = "";
    float *rgba = calloc((size_t)width * (size_t)height * 4, sizeof *rgba);
    assert_non_null(rgba);
    if (lpv_engine_render(lpvt_engine, LPV_TERMS_FULL, rgba, err, sizeof err) != 0)
        fail_msg("render: %s", err);
    return rgba;
}

int lpvt_stage(const char *name, unsigned *calls, double *ms)
{
    const lpv_engine_stats *st = lpv_engine_last_stats(lpvt_engine);
    for (int i = 0; i < st->stage_count; ++i)
        if (strcmp(st->stages[i].name, name) == 0) {
            if (calls)
                *calls = st->stages[i].calls;
            if (ms)
                *ms = st->stages[i].gpu_ms;
            return 1;
        }
    return 0;
}

double lpvt_rand(uint64_t *state, double lo, double hi)
{
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    return lo + (hi - lo) * (double)(*state >> 11) / 9007199254740992.0;
}
