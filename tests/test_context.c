/* test_context.c - headless GL contexts on every backend, the function table,
 * shader building from embedded sources, and the stage timer. Runs on
 * llvmpipe (EGL surfaceless and OSMesa); the EGL device backend either works
 * (a real GPU) or fails with a message. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "context.h"
#include "gl.h"
#include "lpv_shared.h"
#include "shader.h"
#include "timer.h"
#include "test_util.h"

/* Sanitizer build only: Mesa 22.3's OSMesa never frees the buffer object of
 * OSMesaMakeCurrent (one per context) and a block of its first context
 * (see tests/lsan.supp, which has the same line). */
const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void)
{
    return "leak:libOSMesa.so\n";
}

/* ---- helpers ------------------------------------------------------------------ */
static void check_version_45(const lpv_gl_context *ctx)
{
    GLint major = 0, minor = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    assert_true(major * 100 + minor >= 405);
    GLint profile = 0;
    glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
    assert_true(profile & GL_CONTEXT_CORE_PROFILE_BIT);
    assert_non_null(lpv_gl_context_renderer(ctx));
    assert_true(strlen(lpv_gl_context_renderer(ctx)) > 0);
    assert_true(strlen(lpv_gl_context_version(ctx)) > 0);
    assert_string_equal(lpv_gl_context_renderer(ctx), (const char *)glGetString(GL_RENDERER));
}

static lpv_gl_context *create_forced(lpv_backend b, char *err, size_t err_size)
{
    lpv_gl_context_desc desc = {.backend = b, .debug = 0};
    return lpv_gl_context_create(&desc, err, err_size);
}

static void report(const char *what, const lpv_gl_context *ctx)
{
    fprintf(stderr, "[ context  ] %-16s backend %-15s renderer \"%s\", version \"%s\"\n", what,
            lpv_backend_name(lpv_gl_context_backend(ctx)), lpv_gl_context_renderer(ctx),
            lpv_gl_context_version(ctx));
}

/* Runs test_fill.comp over n cells and checks every value it wrote. */
static void run_fill_shader(void)
{
    char err[4096] = "";
    GLuint prog = lpv_program_compute("test_fill.comp", NULL, err, sizeof err);
    if (!prog)
        fail_msg("test_fill.comp: %s", err);
    assert_string_equal(err, "");

    enum { N = 8 };
    GLuint buf = 0;
    glCreateBuffers(1, &buf);
    glNamedBufferStorage(buf, (GLsizeiptr)(N * sizeof(struct LpvCell)), NULL, GL_DYNAMIC_STORAGE_BIT);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_LPV_OUT, buf);
    glUseProgram(prog);
    glDispatchCompute(N / 4, 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);

    struct LpvCell cells[N];
    memset(cells, 0xff, sizeof cells);
    glGetNamedBufferSubData(buf, 0, (GLsizeiptr)sizeof cells, cells);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    for (int i = 0; i < N; i++) {
        /* Exact: the same literal goes through the C and the GLSL compiler. */
        assert_true(cells[i].r[0] == LPV_SH_C0);
        assert_true(cells[i].r[1] == LPV_SH_C1);
        assert_true(cells[i].r[2] == LPV_PI);
        assert_true(cells[i].r[3] == (float)i);
        assert_true(cells[i].g[0] == LPV_PROP_A);
        assert_true(cells[i].g[1] == (float)LPV_DIR_COUNT);
        assert_true(cells[i].g[2] == (float)LPV_MAX_GRID_DIM);
        assert_true(cells[i].g[3] == (float)i + 0.5f);
        assert_true(cells[i].b[0] == -1.0f && cells[i].b[1] == 0.0f && cells[i].b[2] == 1.0f);
        assert_true(cells[i].b[3] == LPV_FP16_MAX);
    }
    glUseProgram(0);
    glDeleteBuffers(1, &buf);
    glDeleteProgram(prog);
}

/* ---- tests ---------------------------------------------------------------------- */
static void test_backend_names(void **state)
{
    (void)state;
    lpv_backend b = LPV_BACKEND_OSMESA;
    assert_int_equal(lpv_backend_parse("auto", &b), 0);
    assert_int_equal(b, LPV_BACKEND_AUTO);
    assert_int_equal(lpv_backend_parse("egl-device", &b), 0);
    assert_int_equal(b, LPV_BACKEND_EGL_DEVICE);
    assert_int_equal(lpv_backend_parse("egl-surfaceless", &b), 0);
    assert_int_equal(b, LPV_BACKEND_EGL_SURFACELESS);
    assert_int_equal(lpv_backend_parse("osmesa", &b), 0);
    assert_int_equal(b, LPV_BACKEND_OSMESA);
    b = LPV_BACKEND_EGL_DEVICE;
    assert_int_equal(lpv_backend_parse("vulkan", &b), -1);
    assert_int_equal(lpv_backend_parse("", &b), -1);
    assert_int_equal(lpv_backend_parse("OSMesa ", &b), -1);
    assert_int_equal(lpv_backend_parse(NULL, &b), -1);
    assert_int_equal(b, LPV_BACKEND_EGL_DEVICE); /* untouched on failure */
    for (int i = LPV_BACKEND_AUTO; i <= LPV_BACKEND_OSMESA; i++) {
        lpv_backend back;
        assert_int_equal(lpv_backend_parse(lpv_backend_name((lpv_backend)i), &back), 0);
        assert_int_equal(back, i);
    }
}

static void test_auto(void **state)
{
    (void)state;
    unsetenv("LPVD_GL_BACKEND");
    char err[2048] = "x";
    lpv_gl_context *ctx = lpv_gl_context_create(NULL, err, sizeof err);
    if (!ctx)
        fail_msg("auto: %s", err);
    assert_string_equal(err, "");
    assert_int_not_equal(lpv_gl_context_backend(ctx), LPV_BACKEND_AUTO);
    check_version_45(ctx);
    report("auto", ctx);
    run_fill_shader();
    lpv_gl_context_destroy(ctx);
}

static void test_egl_device(void **state)
{
    (void)state;
    char err[2048] = "";
    lpv_gl_context *ctx = create_forced(LPV_BACKEND_EGL_DEVICE, err, sizeof err);
    if (ctx) {
        assert_int_equal(lpv_gl_context_backend(ctx), LPV_BACKEND_EGL_DEVICE);
        check_version_45(ctx);
        report("forced", ctx);
        run_fill_shader();
        lpv_gl_context_destroy(ctx);
    } else {
        assert_true(strlen(err) > 0);
        assert_non_null(strstr(err, "egl-device"));
        fprintf(stderr, "[ context  ] egl-device unavailable: %s\n", err);
    }
}

static void test_egl_surfaceless(void **state)
{
    (void)state;
    char err[2048] = "";
    lpv_gl_context *ctx = create_forced(LPV_BACKEND_EGL_SURFACELESS, err, sizeof err);
    if (!ctx)
        fail_msg("egl-surfaceless: %s", err);
    assert_int_equal(lpv_gl_context_backend(ctx), LPV_BACKEND_EGL_SURFACELESS);
    check_version_45(ctx);
    report("forced", ctx);
    run_fill_shader();
    assert_int_equal(lpv_gl_context_make_current(ctx), 0);
    lpv_gl_context_destroy(ctx);
}

static void test_osmesa(void **state)
{
    (void)state;
    char err[2048] = "";
    lpv_gl_context *ctx = create_forced(LPV_BACKEND_OSMESA, err, sizeof err);
    if (!ctx)
        fail_msg("osmesa: %s", err);
    assert_int_equal(lpv_gl_context_backend(ctx), LPV_BACKEND_OSMESA);
    check_version_45(ctx);
    report("forced", ctx);
    run_fill_shader();
    assert_int_equal(lpv_gl_context_make_current(ctx), 0);
    lpv_gl_context_destroy(ctx);
}

static void test_env_override(void **state)
{
    (void)state;
    char err[2048] = "";
    setenv("LPVD_GL_BACKEND", "osmesa", 1);
    lpv_gl_context *ctx = lpv_gl_context_create(NULL, err, sizeof err);
    if (!ctx) {
        unsetenv("LPVD_GL_BACKEND");
        fail_msg("LPVD_GL_BACKEND=osmesa: %s", err);
    }
    assert_int_equal(lpv_gl_context_backend(ctx), LPV_BACKEND_OSMESA);
    report("env osmesa", ctx);
    lpv_gl_context_destroy(ctx);

    /* The descriptor wins over the environment when it is not AUTO. */
    ctx = create_forced(LPV_BACKEND_EGL_SURFACELESS, err, sizeof err);
    if (!ctx) {
        unsetenv("LPVD_GL_BACKEND");
        fail_msg("egl-surfaceless with LPVD_GL_BACKEND=osmesa: %s", err);
    }
    assert_int_equal(lpv_gl_context_backend(ctx), LPV_BACKEND_EGL_SURFACELESS);
    lpv_gl_context_destroy(ctx);

    /* An unknown name is an error, naming the value. */
    setenv("LPVD_GL_BACKEND", "directx", 1);
    ctx = lpv_gl_context_create(NULL, err, sizeof err);
    assert_null(ctx);
    assert_non_null(strstr(err, "directx"));
    assert_non_null(strstr(err, "LPVD_GL_BACKEND"));

    /* "auto" in the environment is the default order. */
    setenv("LPVD_GL_BACKEND", "auto", 1);
    ctx = lpv_gl_context_create(NULL, err, sizeof err);
    if (!ctx) {
        unsetenv("LPVD_GL_BACKEND");
        fail_msg("LPVD_GL_BACKEND=auto: %s", err);
    }
    lpv_gl_context_destroy(ctx);
    unsetenv("LPVD_GL_BACKEND");
}

static void test_invalid_desc(void **state)
{
    (void)state;
    char err[512] = "";
    lpv_gl_context_desc desc = {.backend = (lpv_backend)42};
    assert_null(lpv_gl_context_create(&desc, err, sizeof err));
    assert_true(strlen(err) > 0);
    lpv_gl_context_destroy(NULL); /* no-op */
}

/* Create and destroy repeatedly, alternating backends, with debug output on. */
static void test_create_destroy_cycles(void **state)
{
    (void)state;
    static const lpv_backend order[] = {LPV_BACKEND_EGL_SURFACELESS, LPV_BACKEND_OSMESA, LPV_BACKEND_AUTO};
    for (int round = 0; round < 3; round++) {
        for (size_t i = 0; i < sizeof order / sizeof order[0]; i++) {
            char err[2048] = "";
            lpv_gl_context_desc desc = {.backend = order[i], .debug = 1};
            lpv_gl_context *ctx = lpv_gl_context_create(&desc, err, sizeof err);
            if (!ctx)
                fail_msg("round %d, %s: %s", round, lpv_backend_name(order[i]), err);
            check_version_45(ctx);
            GLuint tex = 0;
            glCreateTextures(GL_TEXTURE_3D, 1, &tex);
            glTextureStorage3D(tex, 1, GL_RGBA16F, 4, 4, 4);
            glDeleteTextures(1, &tex);
            assert_int_equal(glGetError(), GL_NO_ERROR);
            lpv_gl_context_destroy(ctx);
        }
    }
}

/* Two contexts alive at once, of different backends, switched with
 * make_current (the function table follows the backend). */
static void test_two_contexts(void **state)
{
    (void)state;
    char err[2048] = "";
    lpv_gl_context *a = create_forced(LPV_BACKEND_EGL_SURFACELESS, err, sizeof err);
    if (!a)
        fail_msg("egl-surfaceless: %s", err);
    lpv_gl_context *b = create_forced(LPV_BACKEND_OSMESA, err, sizeof err);
    if (!b)
        fail_msg("osmesa: %s", err);
    lpv_gl_context *c = create_forced(LPV_BACKEND_EGL_SURFACELESS, err, sizeof err);
    if (!c)
        fail_msg("egl-surfaceless (second): %s", err);
    for (int i = 0; i < 2; i++) {
        assert_int_equal(lpv_gl_context_make_current(a), 0);
        run_fill_shader();
        assert_int_equal(lpv_gl_context_make_current(b), 0);
        run_fill_shader();
        assert_int_equal(lpv_gl_context_make_current(c), 0);
        run_fill_shader();
    }
    /* Destroying a keeps c's (same EGL display) usable. */
    lpv_gl_context_destroy(a);
    assert_int_equal(lpv_gl_context_make_current(c), 0);
    run_fill_shader();
    lpv_gl_context_destroy(c);
    assert_int_equal(lpv_gl_context_make_current(b), 0);
    run_fill_shader();
    lpv_gl_context_destroy(b);
}

/* Destroying a context that is not current leaves the current one working,
 * without a make_current, across backends (EGL and OSMesa share Mesa's
 * dispatch, so unbinding one must not unbind the other). */
static void test_destroy_not_current(void **state)
{
    (void)state;
    static const lpv_backend pairs[][2] = {
        {LPV_BACKEND_EGL_SURFACELESS, LPV_BACKEND_OSMESA},
        {LPV_BACKEND_OSMESA, LPV_BACKEND_EGL_SURFACELESS},
        {LPV_BACKEND_EGL_SURFACELESS, LPV_BACKEND_EGL_SURFACELESS},
        {LPV_BACKEND_OSMESA, LPV_BACKEND_OSMESA},
    };
    for (size_t i = 0; i < sizeof pairs / sizeof pairs[0]; i++) {
        char err[2048] = "";
        lpv_gl_context *first = create_forced(pairs[i][0], err, sizeof err);
        if (!first)
            fail_msg("%s: %s", lpv_backend_name(pairs[i][0]), err);
        lpv_gl_context *second = create_forced(pairs[i][1], err, sizeof err); /* now current */
        if (!second)
            fail_msg("%s: %s", lpv_backend_name(pairs[i][1]), err);
        lpv_gl_context_destroy(first);
        run_fill_shader(); /* on `second`, still current */
        assert_string_equal((const char *)glGetString(GL_RENDERER), lpv_gl_context_renderer(second));
        /* A failed creation also leaves the current context alone. */
        lpv_gl_context_desc bad = {.backend = LPV_BACKEND_EGL_DEVICE};
        lpv_gl_context *none = lpv_gl_context_create(&bad, err, sizeof err);
        if (none) { /* a real GPU: fine, go back */
            lpv_gl_context_destroy(none);
            assert_int_equal(lpv_gl_context_make_current(second), 0);
        }
        run_fill_shader();
        lpv_gl_context_destroy(second);
    }
}

/* The daemon's pattern: a GL thread creates, uses and destroys its context.
 * cmocka's assertions must stay on the main thread, so the worker reports. */
typedef struct thread_job {
    lpv_backend backend;
    int ok;
    char msg[2048];
} thread_job;

static void *gl_thread(void *arg)
{
    thread_job *job = arg;
    lpv_gl_context_desc desc = {.backend = job->backend};
    lpv_gl_context *ctx = lpv_gl_context_create(&desc, job->msg, sizeof job->msg);
    if (!ctx)
        return NULL;
    char err[1024] = "";
    GLuint prog = lpv_program_compute("test_fill.comp", NULL, err, sizeof err);
    GLuint buf = 0;
    glCreateBuffers(1, &buf);
    glNamedBufferStorage(buf, (GLsizeiptr)(4 * sizeof(struct LpvCell)), NULL, 0);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_LPV_OUT, buf);
    glUseProgram(prog);
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    struct LpvCell cells[4];
    memset(cells, 0, sizeof cells);
    glGetNamedBufferSubData(buf, 0, (GLsizeiptr)sizeof cells, cells);
    job->ok = prog != 0 && glGetError() == GL_NO_ERROR && cells[3].r[0] == LPV_SH_C0 && cells[3].r[3] == 3.0f &&
              lpv_gl_context_make_current(ctx) == 0;
    if (!job->ok)
        snprintf(job->msg, sizeof job->msg, "thread: %s", prog ? "wrong values read back" : err);
    glDeleteBuffers(1, &buf);
    glDeleteProgram(prog);
    lpv_gl_context_destroy(ctx);
    return NULL;
}

static void test_gl_thread(void **state)
{
    (void)state;
    static const lpv_backend order[] = {LPV_BACKEND_AUTO, LPV_BACKEND_OSMESA, LPV_BACKEND_EGL_SURFACELESS};
    for (size_t i = 0; i < sizeof order / sizeof order[0]; i++) {
        thread_job job = {.backend = order[i]};
        pthread_t th;
        assert_int_equal(pthread_create(&th, NULL, gl_thread, &job), 0);
        assert_int_equal(pthread_join(th, NULL), 0);
        if (!job.ok)
            fail_msg("%s: %s", lpv_backend_name(order[i]), job.msg);
    }
}

static lpv_gl_context *g_ctx; /* for the tests below, on the default backend */

static int setup_ctx(void **state)
{
    (void)state;
    char err[2048] = "";
    g_ctx = lpv_gl_context_create(NULL, err, sizeof err);
    if (!g_ctx) {
        fprintf(stderr, "no context: %s\n", err);
        return -1;
    }
    return 0;
}

static int teardown_ctx(void **state)
{
    (void)state;
    lpv_gl_context_destroy(g_ctx);
    g_ctx = NULL;
    return 0;
}

static void test_shader_errors(void **state)
{
    (void)state;
    char err[4096] = "";
    /* A file that is not embedded. */
    assert_null(lpv_shader_text("no_such_shader.comp"));
    assert_int_equal(lpv_program_compute("no_such_shader.comp", NULL, err, sizeof err), 0);
    assert_non_null(strstr(err, "no_such_shader.comp"));
    err[0] = '\0';
    assert_int_equal(lpv_program_graphics("missing.vert", NULL, "missing.frag", NULL, err, sizeof err), 0);
    assert_non_null(strstr(err, "missing.vert"));

    /* Embedded sources are found by name, the shared header among them. */
    assert_non_null(lpv_shader_text("test_fill.comp"));
    assert_non_null(strstr(lpv_shader_text("lpv_shared.h"), "LPV_SH_C0"));

    /* A define that breaks the file: the log names it and the file line. */
    err[0] = '\0';
    GLuint p = lpv_program_compute("test_fill.comp", "#define LPV_TEST_FILL_BREAK 1\n", err, sizeof err);
    assert_int_equal(p, 0);
    assert_non_null(strstr(err, "test_fill.comp"));
    assert_non_null(strstr(err, "compile failed"));
    fprintf(stderr, "[ shader   ] expected failure: %.300s\n", err);
    /* The bad call is on line 15 of test_fill.comp (source string 2; Mesa
     * reports some semantic errors with source 0, so only the line is checked). */
    assert_non_null(strstr(err, ":15("));

    /* Defines are applied. */
    err[0] = '\0';
    p = lpv_program_compute("test_fill.comp", "#define LPV_TEST_UNUSED 1\n#define LPV_TEST_OTHER 2", err, sizeof err);
    assert_int_not_equal(p, 0);
    glDeleteProgram(p);
    assert_int_equal(glGetError(), GL_NO_ERROR);
}

static void test_timer(void **state)
{
    (void)state;
    char err[4096] = "";
    GLuint prog = lpv_program_compute("test_fill.comp", NULL, err, sizeof err);
    if (!prog)
        fail_msg("%s", err);
    GLuint buf = 0;
    glCreateBuffers(1, &buf);
    glNamedBufferStorage(buf, 4096 * (GLsizeiptr)sizeof(struct LpvCell), NULL, 0);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, LPV_SSBO_LPV_OUT, buf);
    glUseProgram(prog);

    /* NULL timers are accepted everywhere. */
    lpv_timer_init(NULL);
    lpv_timer_begin(NULL, "x");
    lpv_timer_count(NULL, 1);
    lpv_timer_end(NULL);
    assert_int_equal(lpv_timer_collect(NULL), 0);
    lpv_timer_destroy(NULL);

    lpv_timer t;
    lpv_timer_init(&t);
    for (int frame = 0; frame < 3; frame++) {
        lpv_timer_begin(&t, "fill");
        glDispatchCompute(1024, 1, 1);
        lpv_timer_count(&t, 1);
        lpv_timer_end(&t);
        lpv_timer_begin(&t, "barrier");
        glMemoryBarrier(GL_ALL_BARRIER_BITS);
        lpv_timer_end(&t);
        lpv_timer_begin(&t, "fill"); /* same name: accumulates */
        glDispatchCompute(512, 1, 1);
        glDispatchCompute(512, 1, 1);
        lpv_timer_count(&t, 2);
        /* no end: collect closes it */
        int n = lpv_timer_collect(&t);
        assert_int_equal(n, 2);
        assert_int_equal(t.stage_count, 2);
        const lpv_timer_stage *fill = lpv_timer_find(&t, "fill");
        const lpv_timer_stage *barrier = lpv_timer_find(&t, "barrier");
        assert_non_null(fill);
        assert_non_null(barrier);
        assert_null(lpv_timer_find(&t, "nothing"));
        assert_string_equal(t.stages[0].name, "fill"); /* order of first appearance */
        assert_int_equal(fill->count, 3);
        assert_int_equal(fill->spans, 2);
        assert_int_equal(barrier->count, 0);
        assert_int_equal(barrier->spans, 1);
        assert_true(fill->gpu_ms >= 0.0);
        assert_true(fill->cpu_ms >= 0.0);
        assert_true(barrier->gpu_ms >= 0.0);
        assert_true(t.gpu_total_ms >= fill->gpu_ms);
        assert_true(t.cpu_total_ms >= fill->cpu_ms);
        assert_int_equal(t.dropped, 0);
        /* Collecting again changes nothing. */
        double g = fill->gpu_ms;
        assert_int_equal(lpv_timer_collect(&t), 2);
        assert_true(lpv_timer_find(&t, "fill")->gpu_ms == g);
        if (frame == 0)
            fprintf(stderr, "[ timer    ] fill: gpu %.3f ms, cpu %.3f ms, %u dispatches\n", fill->gpu_ms,
                    fill->cpu_ms, fill->count);
    }

    /* Too many stage names: the extra ones are dropped and counted. */
    for (int i = 0; i < LPV_TIMER_MAX_STAGES + 3; i++) {
        char name[16];
        snprintf(name, sizeof name, "s%d", i);
        lpv_timer_begin(&t, name);
        lpv_timer_end(&t);
    }
    assert_int_equal(lpv_timer_collect(&t), LPV_TIMER_MAX_STAGES);
    assert_int_equal(t.dropped, 3);

    /* A long name is truncated, not overflowed. */
    lpv_timer_begin(&t, "a-stage-name-much-longer-than-the-thirty-one-characters-kept");
    lpv_timer_end(&t);
    assert_int_equal(lpv_timer_collect(&t), 1);
    assert_int_equal(strlen(t.stages[0].name), LPV_TIMER_NAME_MAX - 1);

    lpv_timer_destroy(&t);
    glUseProgram(0);
    glDeleteBuffers(1, &buf);
    glDeleteProgram(prog);
    assert_int_equal(glGetError(), GL_NO_ERROR);
}

static void test_function_table(void **state)
{
    (void)state;
    /* Every function of the generated list was loaded on this backend. */
    size_t n = 0;
#define LPV_CHECK_LOADED_(type, name) \
    assert_non_null(name);         \
    n++;
    LPV_GL_FUNCTIONS(LPV_CHECK_LOADED_)
#undef LPV_CHECK_LOADED_
    assert_int_equal(n, lpv_gl_function_count);
    assert_true(n > 0);
    assert_non_null(glDispatchCompute);
    assert_non_null(glBindImageTexture);
    assert_non_null(glFramebufferTextureLayer);
    assert_non_null(glCreateBuffers);
    assert_non_null(glObjectLabel);
    assert_string_equal(lpv_gl_error_name(GL_INVALID_OPERATION), "GL_INVALID_OPERATION");
    /* A failing get-proc: the error names the first function, table cleared. */
    char err[256] = "";
    assert_int_equal(lpv_gl_load(NULL, err, sizeof err), -1);
    assert_true(strlen(err) > 0);
    assert_null(lpv_gl_glGetString);
    /* make_current restores the table. */
    assert_int_equal(lpv_gl_context_make_current(g_ctx), 0);
    assert_non_null(lpv_gl_glGetString);
}

/* A get-proc that finds nothing, remembering the first name asked for. */
static char g_first_asked[64];

static void *null_proc(const char *name)
{
    if (!g_first_asked[0])
        snprintf(g_first_asked, sizeof g_first_asked, "%s", name);
    return NULL;
}

static void test_function_table_missing(void **state)
{
    (void)state;
    char err[256] = "";
    char want[128];
    g_first_asked[0] = '\0';
    assert_int_equal(lpv_gl_load(null_proc, err, sizeof err), -1);
    assert_true(strncmp(g_first_asked, "gl", 2) == 0);
    snprintf(want, sizeof want, "missing GL function %s", g_first_asked);
    assert_string_equal(err, want);
    assert_null(lpv_gl_glGetString);
    assert_int_equal(lpv_gl_context_make_current(g_ctx), 0);
    assert_non_null(lpv_gl_glGetString);
    assert_int_equal(glGetError(), GL_NO_ERROR);
}

int main(void)
{
    const struct CMUnitTest standalone[] = {
        cmocka_unit_test(test_backend_names),
        cmocka_unit_test(test_invalid_desc),
        cmocka_unit_test(test_auto),
        cmocka_unit_test(test_egl_device),
        cmocka_unit_test(test_egl_surfaceless),
        cmocka_unit_test(test_osmesa),
        cmocka_unit_test(test_env_override),
        cmocka_unit_test(test_create_destroy_cycles),
        cmocka_unit_test(test_two_contexts),
        cmocka_unit_test(test_gl_thread),
        cmocka_unit_test(test_destroy_not_current),
    };
    const struct CMUnitTest with_context[] = {
        cmocka_unit_test(test_shader_errors),
        cmocka_unit_test(test_timer),
        cmocka_unit_test(test_function_table),
        cmocka_unit_test(test_function_table_missing),
    };
    int failed = cmocka_run_group_tests_name("context", standalone, NULL, NULL);
    failed += cmocka_run_group_tests_name("context_shared", with_context, setup_ctx, teardown_ctx);
    return failed;
}
