/*
 * test_client.c - the C client library (clients/c/lpvc.h) against a real
 * daemon: starts `lpvd serve --socket TMP/lpvd.sock` as a child process and
 * talks to it through every request of SPEC section 4. The daemon is found
 * at $LPVD_BINARY, else ../server/lpvd next to this test's directory; without
 * one (or one without a 'serve' command) every test is skipped, saying why.
 */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cmocka.h>
#include <jansson.h>

#include "lpvc.h"
#include "volume_codec.h"
#include "test_util.h"

static char g_daemon[PATH_MAX + 32];
static char g_sock[PATH_MAX];
static char g_log[PATH_MAX];
static pid_t g_pid = -1;
static char g_skip[PATH_MAX + 256];

static void sleep_ms(int ms)
{
    struct timespec ts = {.tv_sec = ms / 1000, .tv_nsec = (long)(ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

static void print_log(void)
{
    FILE *f = fopen(g_log, "r");
    if (!f)
        return;
    char line[1024];
    fprintf(stderr, "--- daemon log (%s) ---\n", g_log);
    while (fgets(line, sizeof line, f))
        fputs(line, stderr);
    fclose(f);
}

/* Runs `lpvd serve --help` quietly: 0 when the binary has the command. */
static int has_serve(const char *bin)
{
    pid_t p = fork();
    if (p < 0)
        return -1;
    if (p == 0) {
        int fd = open("/dev/null", O_WRONLY);
        if (fd >= 0) {
            dup2(fd, 1);
            dup2(fd, 2);
        }
        execl(bin, bin, "serve", "--help", (char *)NULL);
        _exit(127);
    }
    int st = 0;
    if (waitpid(p, &st, 0) != p)
        return -1;
    return WIFEXITED(st) && WEXITSTATUS(st) == 0 ? 0 : -1;
}

static int find_daemon(void)
{
    const char *env = getenv("LPVD_BINARY");
    if (env && *env) {
        snprintf(g_daemon, sizeof g_daemon, "%s", env);
    } else {
        char self[PATH_MAX];
        ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
        if (n <= 0) {
            snprintf(g_skip, sizeof g_skip, "cannot read /proc/self/exe");
            return -1;
        }
        self[n] = '\0';
        char *slash = strrchr(self, '/');
        if (slash)
            *slash = '\0';
        snprintf(g_daemon, sizeof g_daemon, "%s/../server/lpvd", self);
    }
    if (access(g_daemon, X_OK) != 0) {
        snprintf(g_skip, sizeof g_skip, "no daemon binary at %s (set LPVD_BINARY)", g_daemon);
        return -1;
    }
    if (has_serve(g_daemon) != 0) {
        snprintf(g_skip, sizeof g_skip, "%s has no working 'serve' command", g_daemon);
        return -1;
    }
    return 0;
}

static int group_setup(void **state)
{
    (void)state;
    signal(SIGPIPE, SIG_IGN);
    if (find_daemon() != 0) {
        fprintf(stderr, "test_client: SKIP: %s\n", g_skip);
        return 0;
    }
    const char *dir = lpvt_tmpdir();
    snprintf(g_sock, sizeof g_sock, "%s/lpvd.sock", dir);
    snprintf(g_log, sizeof g_log, "%s/daemon.log", dir);
    g_pid = fork();
    if (g_pid < 0) {
        snprintf(g_skip, sizeof g_skip, "fork: %s", strerror(errno));
        return -1;
    }
    if (g_pid == 0) {
        int fd = open(g_log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd >= 0) {
            dup2(fd, 1);
            dup2(fd, 2);
        }
        execl(g_daemon, g_daemon, "serve", "--socket", g_sock, (char *)NULL);
        _exit(127);
    }
    struct stat st;
    for (int i = 0; i < 1200; i++) { /* 120 s: GL start-up on llvmpipe */
        if (stat(g_sock, &st) == 0 && S_ISSOCK(st.st_mode))
            return 0;
        int status;
        if (waitpid(g_pid, &status, WNOHANG) == g_pid) {
            fprintf(stderr, "test_client: the daemon exited before creating %s\n", g_sock);
            print_log();
            g_pid = -1;
            return -1;
        }
        sleep_ms(100);
    }
    fprintf(stderr, "test_client: no socket at %s after 120 s\n", g_sock);
    print_log();
    return -1;
}

static int group_teardown(void **state)
{
    (void)state;
    if (g_pid > 0) {
        kill(g_pid, SIGTERM);
        int status = 0;
        int done = 0;
        for (int i = 0; i < 300 && !done; i++) { /* R7.4: finishes the tick in flight, then exits */
            if (waitpid(g_pid, &status, WNOHANG) == g_pid)
                done = 1;
            else
                sleep_ms(100);
        }
        if (!done) {
            fprintf(stderr, "test_client: the daemon ignored SIGTERM for 30 s; killing it\n");
            kill(g_pid, SIGKILL);
            waitpid(g_pid, &status, 0);
        } else if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
            fprintf(stderr, "test_client: note: the daemon's exit status after SIGTERM was not 0 (R7.4)\n");
        }
        g_pid = -1;
    }
    return 0;
}

#define REQUIRE_DAEMON()                                                                                     \
    do {                                                                                                     \
        if (g_pid <= 0) {                                                                                    \
            print_message("skipped: %s\n", g_skip);                                                          \
            skip();                                                                                          \
        }                                                                                                    \
    } while (0)

static lpvc *open_client(void)
{
    char err[512];
    lpvc_connect_desc d = {.address = g_sock, .client_name = "test_client", .timeout_ms = 300000};
    lpvc *c = lpvc_connect_with(&d, err, sizeof err);
    if (!c) {
        fprintf(stderr, "connect: %s\n", err);
        print_log();
    }
    assert_non_null(c);
    return c;
}

/* Checks a call's status, printing the error when it failed. */
#define OK(c, call)                                                                                          \
    do {                                                                                                     \
        if ((call) != 0) {                                                                                   \
            fprintf(stderr, "%s:%d: %s failed: %s (%d): %s\n", __FILE__, __LINE__, #call, lpvc_error_name(c), \
                    lpvc_error_code(c), lpvc_error_message(c));                                             \
            fail();                                                                                          \
        }                                                                                                    \
    } while (0)

static json_t *last_reply(lpvc *c)
{
    json_t *o = json_loads(lpvc_last_reply(c), 0, NULL);
    assert_non_null(o);
    return o;
}

/* ---- tests ----------------------------------------------------------------- */

static void test_hello(void **state)
{
    (void)state;
    REQUIRE_DAEMON();
    lpvc *c = open_client();
    json_t *h = json_loads(lpvc_hello_reply(c), 0, NULL);
    assert_non_null(h);
    assert_int_equal(json_integer_value(json_object_get(h, "version")), 1);
    assert_true(json_is_string(json_object_get(h, "server")));
    assert_true(json_is_integer(json_object_get(h, "session")));
    json_decref(h);
    OK(c, lpvc_bye(c));
    /* After BYE the connection is closed: calls fail with CLOSED. */
    assert_int_equal(lpvc_tick(c, NULL), -1);
    assert_int_equal(lpvc_error_code(c), LPVC_ERR_CLOSED);
    lpvc_close(c);
}

/* R4.12: the knobs come from the server's description; the library checks
 * values against it before sending, and what it lets through CONFIG takes. */
static void test_knob_description(void **state)
{
    (void)state;
    REQUIRE_DAEMON();
    lpvc *c = open_client();
    const lpvc_knob *k = NULL;
    size_t n = lpvc_knobs(c, &k);
    assert_true(n > 0);
    for (size_t i = 0; i < n; i++) {
        assert_non_null(k[i].name);
        assert_true(k[i].min <= k[i].max);
        char err[256];
        /* the default is allowed, and CONFIG takes it and echoes it */
        assert_int_equal(lpvc_knob_check(&k[i], k[i].def, err, sizeof err), 0);
        lpvc_setting one = {k[i].name, k[i].def};
        lpvc_config cfg = {.settings = &one, .setting_count = 1};
        OK(c, lpvc_config_set(c, &cfg));
        json_t *r = last_reply(c);
        json_t *v = json_object_get(json_object_get(r, "config"), k[i].name);
        assert_non_null(v);
        double got = json_is_boolean(v) ? (json_is_true(v) ? 1.0 : 0.0) : json_number_value(v);
        assert_true(fabs(got - k[i].def) <= 1e-6 * fmax(1.0, fabs(k[i].def)));
        json_decref(r);
        if (k[i].type == LPVC_KNOB_BOOL)
            continue;
        /* above the range: refused here, naming the knob, without a request */
        lpvc_setting over = {k[i].name, k[i].max + fmax(1.0, fabs(k[i].max))};
        cfg.settings = &over;
        assert_int_equal(lpvc_config_set(c, &cfg), -1);
        assert_int_equal(lpvc_error_code(c), LPVC_ERR_USAGE);
        assert_non_null(strstr(lpvc_error_message(c), k[i].name));
        double parsed;
        assert_int_equal(lpvc_knob_parse(&k[i], "x", &parsed, err, sizeof err), -1);
        assert_non_null(strstr(err, k[i].name));
    }
    lpvc_setting unknown = {"no_such_knob", 1};
    lpvc_config cfg = {.settings = &unknown, .setting_count = 1};
    assert_int_equal(lpvc_config_set(c, &cfg), -1);
    assert_int_equal(lpvc_error_code(c), LPVC_ERR_USAGE);
    size_t np = 0;
    const char *const *presets = lpvc_presets(c, &np);
    assert_true(np > 0);
    json_t *h = json_loads(lpvc_hello_reply(c), 0, NULL);
    assert_int_equal(np, json_array_size(json_object_get(h, "presets")));
    /* R4.12: each knob names its technique and what a change recomputes */
    json_t *knobs = json_object_get(h, "knobs");
    int lpv_knobs = 0, shading_only = 0;
    for (size_t i = 0; i < json_array_size(knobs); i++) {
        json_t *kj = json_array_get(knobs, i);
        const char *tech = json_string_value(json_object_get(kj, "technique"));
        json_t *touches = json_object_get(kj, "touches");
        assert_non_null(tech);
        assert_true(json_is_array(touches) && json_array_size(touches) >= 1);
        lpv_knobs += strcmp(tech, "lpv") == 0;
        shading_only += json_array_size(touches) == 1 &&
                        strcmp(json_string_value(json_array_get(touches, 0)), "shading") == 0;
    }
    assert_true(lpv_knobs > 0 && shading_only > 0);
    json_decref(h);
    lpvc_config pc = {.preset = presets[np - 1]};
    OK(c, lpvc_config_set(c, &pc));
    OK(c, lpvc_bye(c));
    lpvc_close(c);
}

static void test_connect_refused(void **state)
{
    (void)state;
    char err[512];
    char path[PATH_MAX];
    snprintf(path, sizeof path, "%s/nobody-here.sock", lpvt_tmpdir());
    lpvc *c = lpvc_connect(path, NULL, err, sizeof err);
    assert_null(c);
    assert_non_null(strstr(err, "nobody-here.sock"));
}

static void test_errors_keep_the_connection(void **state)
{
    (void)state;
    REQUIRE_DAEMON();
    lpvc *c = open_client();
    /* R4.3: no --scene-root configured, every path is refused. */
    assert_int_equal(lpvc_scene_load_file(c, "cornell-box.glb"), -1);
    assert_int_equal(lpvc_error_code(c), 12);
    assert_string_equal(lpvc_error_name(c), "PATH_REFUSED");
    assert_true(strlen(lpvc_error_message(c)) > 0);
    /* R4.4: garbage bytes are not a .glb. */
    static const char junk[] = "this is not a glb file at all";
    assert_int_equal(lpvc_scene_load_glb(c, junk, sizeof junk), -1);
    assert_int_equal(lpvc_error_code(c), 11);
    assert_string_equal(lpvc_error_name(c), "SCENE_INVALID");
    /* R2.8: an unknown type. */
    assert_int_equal(lpvc_request_raw(c, 0x0042, "{}", NULL, 0, NULL, NULL), -1);
    assert_int_equal(lpvc_error_code(c), 6);
    /* R4.7: the attachment must be count x 24 bytes. */
    float six[6] = {0, 0, 0, 0, 1, 0};
    assert_int_equal(lpvc_request_raw(c, 0x000D, "{\"count\": 2}", six, sizeof six, NULL, NULL), -1);
    assert_int_equal(lpvc_error_code(c), 7);
    assert_string_equal(lpvc_error_name(c), "BAD_FIELD");
    /* R2.9: a field of the wrong type. */
    assert_int_equal(lpvc_config_json(c, "{\"iterations\": \"many\"}"), -1);
    assert_int_equal(lpvc_error_code(c), 7);
    assert_non_null(strstr(lpvc_error_message(c), "iterations"));
    /* R4.6: a grid over the server's limit. */
    lpvc_config big = {.grid = {100000, 100000, 100000}};
    assert_int_equal(lpvc_config_set(c, &big), -1);
    assert_int_equal(lpvc_error_code(c), 13);
    /* Client-side refusal: not a JSON object. */
    assert_int_equal(lpvc_scene_update(c, "[1, 2]"), -1);
    assert_int_equal(lpvc_error_code(c), LPVC_ERR_USAGE);
    /* None of these closed the connection. */
    int64_t tick = -1;
    OK(c, lpvc_tick(c, &tick));
    assert_true(tick >= 1);
    OK(c, lpvc_bye(c));
    lpvc_close(c);
}

static float max_abs(const float *v, size_t n)
{
    float m = 0.0f;
    for (size_t i = 0; i < n; i++)
        if (fabsf(v[i]) > m)
            m = fabsf(v[i]);
    return m;
}

static void test_tick_volume_query(void **state)
{
    (void)state;
    REQUIRE_DAEMON();
    lpvc *c = open_client();
    /* the local lookup below is R5.7's on the LPV's SH cells (lpv named: the
     * default technique is auto since issue 30), exact for one volume per
     * cascade: normal bins and the far field (the LPV's defaults) are off here
     * (docs/protocol.md) */
    OK(c, lpvc_config_json(c, "{\"technique\": \"lpv\", \"normal_bins\": false, \"far_field\": false}"));
    int64_t tick = -1;
    OK(c, lpvc_tick(c, &tick));
    assert_true(tick >= 1);
    json_t *r = last_reply(c);
    assert_true(json_is_integer(json_object_get(r, "revision")));
    assert_true(json_is_object(json_object_get(r, "stats")));
    json_decref(r);

    lpvc_volume v32, v16, vnone;
    lpvc_volume_desc d32 = {.format = "fp32", .compression = "zstd"};
    lpvc_volume_desc d16 = {.format = "fp16", .compression = "zstd"};
    lpvc_volume_desc dnone = {.format = "fp32", .compression = "none"};
    OK(c, lpvc_get_volume(c, &d32, &v32));
    OK(c, lpvc_get_volume(c, &d16, &v16));
    OK(c, lpvc_get_volume(c, &dnone, &vnone));
    assert_true(v32.cells > 0);
    assert_int_equal(v32.cells, (size_t)v32.dims[0] * v32.dims[1] * v32.dims[2]);
    assert_true(v32.cell_size > 0.0f);
    assert_string_equal(v32.format, "fp32");
    assert_string_equal(v16.format, "fp16");
    assert_true(v32.keyframe);
    assert_int_equal(v32.tick, tick);
    assert_int_equal(v16.tick, tick);
    for (int a = 0; a < 3; a++)
        assert_int_equal(v16.dims[a], v32.dims[a]);
    /* zstd and none carry the same bytes. */
    assert_memory_equal(v32.data, vnone.data, v32.cells * 12 * sizeof(float));
    /* Finite, c0 >= 0 (propagation.md §4), some light somewhere. */
    double flux = 0.0;
    for (size_t i = 0; i < v32.cells; i++) {
        const float *cell = v32.data + 12 * i;
        for (int k = 0; k < 12; k++)
            assert_true(isfinite(cell[k]));
        for (int ch = 0; ch < 3; ch++) {
            assert_true(cell[4 * ch] >= 0.0f);
            flux += cell[4 * ch];
        }
    }
    assert_true(flux > 0.0);
    /* fp16 = fp32 rounded (R5.4): relative 2^-11 plus the subnormal step. */
    float m = max_abs(v32.data, v32.cells * 12);
    for (size_t i = 0; i < v32.cells * 12; i++) {
        float a = v32.data[i], b = v16.data[i];
        float tol = fabsf(a) * (1.0f / 1024.0f) + 1e-7f + (fabsf(a) > 65504.0f ? fabsf(a) : 0.0f);
        if (!(fabsf(a - b) <= tol)) {
            fprintf(stderr, "value %zu: fp32 %g fp16 %g (max %g)\n", i, (double)a, (double)b, (double)m);
            fail();
        }
    }

    /* QUERY_IRRADIANCE = the local lookup of propagation.md §6 on the fp32
     * volume of the same tick. Points on a lattice through the grid, normals
     * along the six axes and one diagonal. */
    enum { N = 7 * 27 };
    float pts[N * 3], nrm[N * 3], rgb[N * 3];
    static const float dirs[7][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {1, 1, 1}};
    size_t n = 0;
    for (int i = 0; i < 27; i++)
        for (int k = 0; k < 7; k++, n++) {
            int f[3] = {i % 3, (i / 3) % 3, i / 9};
            for (int a = 0; a < 3; a++) {
                pts[3 * n + a] = v32.origin[a] + (0.1f + 0.4f * (float)f[a]) * (float)v32.dims[a] * v32.cell_size;
                nrm[3 * n + a] = dirs[k][a];
            }
        }
    OK(c, lpvc_query_irradiance(c, pts, nrm, N, rgb));
    r = last_reply(c);
    assert_int_equal(json_integer_value(json_object_get(r, "count")), N);
    assert_int_equal(json_integer_value(json_object_get(r, "tick")), tick);
    json_decref(r);
    /* the volume describes itself (SPEC R5.9 - R5.11): the technique's SH layout */
    assert_int_equal(v32.layout_version, LPVP_VOLUME_LAYOUT_VERSION);
    assert_true(v32.technique[0] != '\0');
    assert_int_equal(v32.values_per_cell, LPVP_VALUES_PER_CELL);
    assert_int_equal(v32.volumes_per_level, 1);
    assert_true(v32.sh_values);
    assert_null(v32.index);
    char why[256];
    assert_int_equal(lpvc_volume_lookup_check(&v32, why, sizeof why), 0);
    float local[N * 3];
    for (size_t i = 0; i < N; i++)
        assert_int_equal(lpvc_volume_irradiance(&v32, pts + 3 * i, nrm + 3 * i, local + 3 * i), 0);
    {
        /* a layout the lookup does not read is refused, naming it */
        lpvc_volume other = v32;
        other.values_per_cell = 4;
        other.sh_values = false;
        float e[3] = {1, 1, 1};
        assert_int_equal(lpvc_volume_irradiance(&other, pts, nrm, e), -1);
        assert_true(e[0] == 0.0f && e[1] == 0.0f && e[2] == 0.0f);
        assert_int_equal(lpvc_volume_lookup_check(&other, why, sizeof why), -1);
        assert_non_null(strstr(why, "4 values per cell"));
    }
    float emax = fmaxf(max_abs(local, N * 3), max_abs(rgb, N * 3));
    assert_true(emax > 0.0f);
    for (size_t i = 0; i < N * 3; i++) {
        assert_true(isfinite(rgb[i]) && rgb[i] >= 0.0f);
        if (!(fabsf(rgb[i] - local[i]) <= 1e-3f * emax)) {
            fprintf(stderr, "query %zu: server %g, local %g (max %g)\n", i / 3, (double)rgb[i], (double)local[i],
                    (double)emax);
            fail();
        }
    }
    /* An empty query is fine too. */
    OK(c, lpvc_query_irradiance(c, NULL, NULL, 0, NULL));

    lpvc_volume_free(&v32);
    lpvc_volume_free(&v16);
    lpvc_volume_free(&vnone);
    OK(c, lpvc_bye(c));
    lpvc_close(c);
}

/* GET_VOLUME content "levels" (SPEC R5.13): the octree's levels and index
 * volume, placed as the header says; the merged volume is eq. 10 of them. */
static void test_octree_levels(void **state)
{
    (void)state;
    REQUIRE_DAEMON();
    lpvc *c = open_client();
    lpvc_config g8 = {.grid = {8, 8, 8}};
    OK(c, lpvc_config_set(c, &g8));
    OK(c, lpvc_config_json(c, "{\"technique\": \"lpv\"}"));
    OK(c, lpvc_tick(c, NULL));
    lpvc_volume v;
    /* a technique without levels: refused, naming "content" */
    assert_int_equal(lpvc_get_volume(c, &(lpvc_volume_desc){.content = "levels"}, &v), -1);
    assert_string_equal(lpvc_error_name(c), "BAD_FIELD");
    assert_non_null(strstr(lpvc_error_message(c), "content"));
    assert_int_equal(lpvc_get_volume(c, &(lpvc_volume_desc){.content = "everything"}, &v), -1);
    assert_string_equal(lpvc_error_name(c), "BAD_FIELD");

    OK(c, lpvc_config_json(c, "{\"technique\": \"octree\"}"));
    int64_t tick = -1;
    OK(c, lpvc_tick(c, &tick));
    lpvc_volume merged, lv, lv16;
    OK(c, lpvc_get_volume(c, &(lpvc_volume_desc){.format = "fp32", .compression = "none"}, &merged));
    OK(c, lpvc_get_volume(c, &(lpvc_volume_desc){.format = "fp32", .content = "levels"}, &lv));
    OK(c, lpvc_get_volume(c, &(lpvc_volume_desc){.format = "fp16", .compression = "none", .content = "levels"}, &lv16));
    assert_string_equal(merged.content, "merged");
    assert_string_equal(lv.content, "levels");
    assert_string_equal(lv.technique, "octree");
    assert_int_equal(lv.tick, tick);
    assert_int_equal(merged.level_count, 0);
    const int n = 8, l = 4;
    assert_int_equal(lv.level_count, l);
    assert_int_equal(lv.cascade_count, 1);
    size_t total = 0;
    for (int i = 0; i < l; i++) {
        const lpvc_cascade *lev = &lv.levels[i];
        for (int a = 0; a < 3; a++) {
            assert_int_equal(lev->dims[a], n >> i);
            assert_true(lev->origin[a] == merged.origin[a]);
        }
        assert_true(fabsf(lev->cell_size - ldexpf(merged.cell_size, i)) <= 1e-6f * lev->cell_size);
        assert_int_equal(lev->cells, (size_t)(n >> i) * (size_t)(n >> i) * (size_t)(n >> i));
        assert_true(lev->data == lv.data + 12 * total);
        total += lev->cells;
    }
    assert_int_equal(lv.total_cells, total);
    assert_true(lv.cascades[0].data == lv.levels[0].data);
    assert_int_equal(lv.index_count, (size_t)(n * n * n));
    assert_int_equal(lv.index_level, 0);
    assert_int_equal(lv.index_values_per_cell, 1);
    assert_int_equal(lv16.index_count, lv.index_count);
    assert_memory_equal(lv16.index, lv.index, lv.index_count * sizeof(uint32_t)); /* u32 whatever the format */
    /* eq. 10: M(x) = level I(x) at x >> I(x); a level I(x) < l - 1 holds light there */
    int lit_from_coarser = 0;
    for (int z = 0; z < n; z++)
        for (int y = 0; y < n; y++)
            for (int x = 0; x < n; x++) {
                size_t cell = (size_t)x + (size_t)n * ((size_t)y + (size_t)n * (size_t)z);
                uint32_t i = lv.index[cell];
                assert_true(i < (uint32_t)l);
                const lpvc_cascade *lev = &lv.levels[i];
                int m = n >> i;
                size_t at = (size_t)(x >> i) + (size_t)m * ((size_t)(y >> i) + (size_t)m * (size_t)(z >> i));
                assert_memory_equal(merged.data + 12 * cell, lev->data + 12 * at, 12 * sizeof(float));
                float any = 0.0f;
                for (int k = 0; k < 12; k++)
                    any = fmaxf(any, fabsf(lev->data[12 * at + k]));
                if (i + 1 < (uint32_t)l)
                    assert_true(any > 0.0f);
                lit_from_coarser += i > 0 && any > 0.0f;
            }
    assert_true(max_abs(lv.data, lv.total_cells * 12) > 0.0f);
    (void)lit_from_coarser;
    /* R5.7's lookup is for the merged grid: refused on "levels", naming it */
    char why[256];
    assert_int_equal(lpvc_volume_lookup_check(&merged, why, sizeof why), 0);
    assert_int_equal(lpvc_volume_lookup_check(&lv, why, sizeof why), -1);
    assert_non_null(strstr(why, "\"levels\""));
    float p[3] = {merged.origin[0] + 0.5f, merged.origin[1] + 0.5f, merged.origin[2] + 0.5f}, nn[3] = {0, 1, 0}, e[3];
    assert_int_equal(lpvc_volume_irradiance(&lv, p, nn, e), -1);
    lpvc_volume_free(&merged);
    lpvc_volume_free(&lv);
    lpvc_volume_free(&lv16);
    OK(c, lpvc_bye(c));
    lpvc_close(c);
}

/* The points where a volume's local lookup is held to QUERY_IRRADIANCE:
 * 4 x 4 x 4 places across its box, each with the 6 axes and a diagonal as
 * normals. The server's answers go to rgb, the local ones to local (each
 * LOOKUP_POINTS x 3); returns the largest value of either. */
enum { LOOKUP_POINTS = 7 * 64 };
static float query_and_look_up(lpvc *c, const lpvc_volume *v, float *rgb, float *local)
{
    float pts[LOOKUP_POINTS * 3], nrm[LOOKUP_POINTS * 3];
    static const float dirs[7][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {1, 1, 1}};
    size_t n = 0;
    for (int i = 0; i < 64; i++)
        for (int k = 0; k < 7; k++, n++) {
            int g[3] = {i % 4, (i / 4) % 4, i / 16};
            for (int a = 0; a < 3; a++) {
                /* other fractions per axis: no two corners exactly as far from the shifted point (a tie that the
                 * GPU's float distances may break the other way; R5.14 keeps the lower corner) */
                static const float at[3] = {0.07f, 0.11f, 0.05f}, step[3] = {0.29f, 0.27f, 0.31f};
                pts[3 * n + a] = v->origin[a] + (at[a] + step[a] * (float)g[a]) * (float)v->dims[a] * v->cell_size;
                nrm[3 * n + a] = dirs[k][a];
            }
        }
    OK(c, lpvc_query_irradiance(c, pts, nrm, LOOKUP_POINTS, rgb));
    for (size_t i = 0; i < LOOKUP_POINTS; i++)
        assert_int_equal(lpvc_volume_irradiance(v, pts + 3 * i, nrm + 3 * i, local + 3 * i), 0);
    const float emax = fmaxf(max_abs(local, LOOKUP_POINTS * 3), max_abs(rgb, LOOKUP_POINTS * 3));
    assert_true(emax > 0.0f);
    return emax;
}

/* Technique iv (SPEC R5.14): the volume of voxels with its occupancy index
 * and iv_neighbours, looked up locally (lpvc_volume_irradiance) as the
 * server's QUERY_IRRADIANCE answers; the "ao" frame term is refused with
 * BAD_FIELD naming terms unless the session has technique iv with iv_ao on,
 * and is then a linear fraction (units "1"). */
static void test_iv_volume(void **state)
{
    (void)state;
    REQUIRE_DAEMON();
    lpvc *c = open_client();
    float eye[3] = {0, 1, 3.9f}, target[3] = {0, 1, 0};
    lpvc_camera cam = {.eye = eye, .target = target, .fov_deg = 40, .width = 48, .height = 32};
    OK(c, lpvc_camera_set(c, &cam));
    OK(c, lpvc_config_json(c, "{\"technique\": \"lpv\"}"));
    OK(c, lpvc_tick(c, NULL));
    lpvc_frame f;
    const lpvc_frame_desc ao = {.format = "rgba8", .compression = "none", .terms = "ao"};
    assert_int_equal(lpvc_get_frame(c, &ao, &f), -1);
    assert_string_equal(lpvc_error_name(c), "BAD_FIELD");
    assert_non_null(strstr(lpvc_error_message(c), "terms"));
    OK(c, lpvc_config_json(c, "{\"technique\": \"iv\", \"iv_resolution\": 16, \"iv_rays\": 32, \"iv_bounces\": 2, "
                              "\"iv_neighbours\": 6}"));
    int64_t tick = -1;
    OK(c, lpvc_tick(c, &tick));
    assert_int_equal(lpvc_get_frame(c, &ao, &f), -1); /* iv_ao off */
    assert_string_equal(lpvc_error_name(c), "BAD_FIELD");
    assert_non_null(strstr(lpvc_error_message(c), "iv_ao"));

    lpvc_volume v, v16;
    OK(c, lpvc_get_volume(c, &(lpvc_volume_desc){.format = "fp32", .compression = "none"}, &v));
    OK(c, lpvc_get_volume(c, &(lpvc_volume_desc){.format = "fp16"}, &v16));
    assert_int_equal(v.tick, tick);
    assert_string_equal(v.technique, "iv");
    assert_true(v.iv_voxels);
    assert_string_equal(v.units, "W/(m^2 sr)");
    assert_int_equal(v.iv_neighbours, 6);
    assert_int_equal(v.cascade_count, 1);
    assert_true(v.sh_values && v.values_per_cell == 12 && v.volumes_per_level == 1);
    assert_int_equal(v.index_count, v.cells);
    assert_int_equal(v.index_level, 0);
    assert_int_equal(v.index_values_per_cell, 1);
    for (int a = 0; a < 3; a++)
        assert_int_equal(v.index_dims[a], v.dims[a]);
    assert_true(v.dims[0] == 17 || v.dims[1] == 17 || v.dims[2] == 17); /* 16 voxels along the longest side + 1 */
    size_t held = 0;
    for (size_t i = 0; i < v.index_count; i++) {
        assert_true(v.index[i] <= 1);
        held += v.index[i];
    }
    assert_true(held > 0 && held < v.cells);
    assert_memory_equal(v16.index, v.index, v.index_count * sizeof(uint32_t)); /* u32 whatever the format */
    assert_true(v16.iv_voxels && v16.iv_neighbours == 6);
    char why[256];
    assert_int_equal(lpvc_volume_lookup_check(&v, why, sizeof why), 0);
    {
        /* without its index the volume is not R5.14's: refused, naming it */
        lpvc_volume bare = v;
        bare.index = NULL;
        bare.index_count = 0;
        float e[3] = {1, 1, 1};
        assert_int_equal(lpvc_volume_lookup_check(&bare, why, sizeof why), -1);
        assert_int_equal(lpvc_volume_irradiance(&bare, eye, target, e), -1);
        assert_true(e[0] == 0.0f && e[1] == 0.0f && e[2] == 0.0f);
    }

    /* QUERY_IRRADIANCE = R5.14's lookup on the fp32 volume of the same tick */
    enum { N = LOOKUP_POINTS };
    float rgb[N * 3], local[N * 3];
    const float emax = query_and_look_up(c, &v, rgb, local);
    size_t lit = 0;
    for (size_t i = 0; i < N * 3; i++) {
        assert_true(isfinite(rgb[i]) && rgb[i] >= 0.0f);
        lit += local[i] > 1e-3f * emax;
        if (!(fabsf(rgb[i] - local[i]) <= 1e-5f * emax)) { /* measured: 8.5e-7 of the largest */
            fprintf(stderr, "query %zu: server %g, local %g (max %g)\n", i / 3, (double)rgb[i], (double)local[i],
                    (double)emax);
            fail();
        }
    }
    assert_true(lit > N); /* a good share of the probes sees light */
    lpvc_volume_free(&v);
    lpvc_volume_free(&v16);

    /* with iv_ao on: the ao frame, grey, a fraction of 255 */
    OK(c, lpvc_config_json(c, "{\"iv_ao\": true}"));
    OK(c, lpvc_tick(c, NULL));
    OK(c, lpvc_get_frame(c, &(lpvc_frame_desc){.format = "rgba8", .compression = "none", .terms = "ao",
                                               .transparent = true},
                         &f));
    assert_string_equal(f.terms, "ao");
    json_t *hdr = json_loads(f.header_json, 0, NULL);
    assert_non_null(hdr);
    assert_string_equal(json_string_value(json_object_get(hdr, "units")), "1");
    assert_null(json_object_get(hdr, "exposure_ev"));
    json_decref(hdr);
    size_t seen = 0, open = 0;
    for (size_t i = 0; i < f.size; i += 4) {
        if (f.data[i + 3] == 0)
            continue;
        assert_true(f.data[i] == f.data[i + 1] && f.data[i] == f.data[i + 2]);
        seen++;
        open += f.data[i] > 128;
    }
    assert_true(seen > 0 && open > 0);
    lpvc_frame_free(&f);
    OK(c, lpvc_bye(c));
    lpvc_close(c);
}

/* Technique probes with content "visibility" (SPEC R5.15): the merged SH
 * volume plus every probe's record, f32 whatever the format, looked up
 * locally (lpvc_volume_irradiance: the probes weighted by their distance
 * maps) as the server's QUERY_IRRADIANCE answers; refused with BAD_FIELD
 * naming content for a technique without probes. */
static void test_probes_visibility(void **state)
{
    (void)state;
    REQUIRE_DAEMON();
    lpvc *c = open_client();
    OK(c, lpvc_config_json(c, "{\"technique\": \"lpv\"}"));
    OK(c, lpvc_tick(c, NULL));
    lpvc_volume v, v16, merged;
    assert_int_equal(lpvc_get_volume(c, &(lpvc_volume_desc){.content = "visibility"}, &v), -1);
    assert_string_equal(lpvc_error_name(c), "BAD_FIELD");
    assert_non_null(strstr(lpvc_error_message(c), "content"));
    OK(c, lpvc_config_json(c, "{\"technique\": \"probes\", \"grid\": 8, \"probes_rays\": 32}"));
    int64_t tick = -1;
    OK(c, lpvc_tick(c, &tick));
    OK(c, lpvc_get_volume(c, &(lpvc_volume_desc){.format = "fp32", .content = "visibility"}, &v));
    OK(c, lpvc_get_volume(c, &(lpvc_volume_desc){.format = "fp16", .compression = "none", .content = "visibility"},
                          &v16));
    OK(c, lpvc_get_volume(c, &(lpvc_volume_desc){.format = "fp32"}, &merged));
    assert_int_equal(v.tick, tick);
    assert_string_equal(v.technique, "probes");
    assert_string_equal(v.content, "visibility");
    assert_string_equal(merged.content, "merged");
    assert_null(merged.visibility);
    assert_int_equal(v.irradiance_side, 6);
    assert_int_equal(v.distance_side, 8);
    assert_int_equal(v.values_per_probe, 4 + 3 * 36 + 2 * 64);
    assert_int_equal(v.visibility_floats, v.total_cells * (size_t)v.values_per_probe);
    assert_int_equal(v.total_cells, merged.total_cells);
    /* the SH part is the merged volume; the visibility is f32 in either format */
    assert_memory_equal(v.data, merged.data, merged.total_cells * 12 * sizeof(float));
    assert_int_equal(v16.visibility_floats, v.visibility_floats);
    assert_memory_equal(v16.visibility, v.visibility, v.visibility_floats * sizeof(float));
    size_t active = 0;
    for (size_t i = 0; i < v.total_cells; i++) {
        const float *r = v.visibility + i * (size_t)v.values_per_probe;
        assert_true(r[3] == 0.0f || r[3] == 1.0f);
        active += r[3] == 1.0f;
        for (int a = 0; a < 3; a++)
            assert_true(fabsf(r[a]) < 0.5f * v.cell_size);
        for (int k = 4; k < v.values_per_probe; k++)
            assert_true(isfinite(r[k]) && r[k] >= 0.0f);
    }
    assert_true(active > 0);

    /* QUERY_IRRADIANCE = R5.15's lookup on the volume of the same tick */
    enum { N = LOOKUP_POINTS };
    float rgb[N * 3], local[N * 3];
    const float emax = query_and_look_up(c, &v, rgb, local);
    size_t off = 0, lit = 0;
    float worst = 0.0f;
    for (size_t i = 0; i < N * 3; i++) {
        assert_true(isfinite(rgb[i]) && rgb[i] >= 0.0f);
        lit += local[i] > 1e-3f * emax;
        worst = fmaxf(worst, fabsf(rgb[i] - local[i]) / emax);
        off += !(fabsf(rgb[i] - local[i]) <= 1e-4f * emax);
    }
    fprintf(stderr, "probes: %zu of %d values differ from the server's by more than 1e-4 of the largest (worst %g)\n",
            off, N * 3, (double)worst);
    assert_true(off <= N * 3 / 50); /* the thresholds, where the GPU's rounding may fall the other way */
    assert_true(lit > N);
    lpvc_volume_free(&v);
    lpvc_volume_free(&v16);
    lpvc_volume_free(&merged);
    OK(c, lpvc_bye(c));
    lpvc_close(c);
}

static void test_frames(void **state)
{
    (void)state;
    REQUIRE_DAEMON();
    lpvc *c = open_client();
    float eye[3] = {0, 1, 3.9f}, target[3] = {0, 1, 0};
    lpvc_camera cam = {.eye = eye, .target = target, .fov_deg = 40, .width = 48, .height = 32};
    OK(c, lpvc_camera_set(c, &cam));
    OK(c, lpvc_tick(c, NULL));

    lpvc_frame f;
    lpvc_frame_desc rgba = {.format = "rgba8", .compression = "zstd", .terms = "full"};
    OK(c, lpvc_get_frame(c, &rgba, &f));
    assert_string_equal(f.format, "rgba8");
    assert_int_equal(f.width, 48);
    assert_int_equal(f.height, 32);
    assert_int_equal(f.size, (size_t)48 * 32 * 4);
    size_t lit = 0;
    for (size_t i = 0; i < f.size; i += 4)
        lit += f.data[i] || f.data[i + 1] || f.data[i + 2];
    assert_true(lit > 0);
    lpvc_frame_free(&f);

    lpvc_frame_desc png = {.format = "png", .terms = "indirect"};
    OK(c, lpvc_get_frame(c, &png, &f));
    assert_string_equal(f.format, "png");
    assert_string_equal(f.terms, "indirect");
    assert_true(f.size > 8);
    assert_memory_equal(f.data, "\x89PNG\r\n\x1a\n", 8);
    lpvc_frame_free(&f);

    /* SPEC R6.4: a fixed EV and a transparent background are honoured and echoed; a bad exposure is refused */
    lpvc_frame_desc fixed = {.format = "rgba8", .compression = "none", .exposure = "-3.5", .transparent = true};
    OK(c, lpvc_get_frame(c, &fixed, &f));
    json_t *hdr = json_loads(f.header_json, 0, NULL);
    assert_non_null(hdr);
    assert_true(json_real_value(json_object_get(hdr, "exposure_ev")) == -3.5);
    assert_string_equal(json_string_value(json_object_get(hdr, "exposure")), "fixed");
    assert_true(json_is_true(json_object_get(hdr, "transparent")));
    json_decref(hdr);
    size_t clear = 0;
    for (size_t i = 0; i < f.size; i += 4)
        clear += f.data[i + 3] == 0;
    lpvc_frame_free(&f);
    OK(c, lpvc_get_frame(c, &rgba, &f)); /* default: auto exposure, opaque */
    hdr = json_loads(f.header_json, 0, NULL);
    assert_non_null(hdr);
    assert_string_equal(json_string_value(json_object_get(hdr, "exposure")), "auto");
    json_decref(hdr);
    for (size_t i = 0; i < f.size; i += 4)
        assert_int_equal(f.data[i + 3], 255);
    print_message("transparent frame: %zu of %zu pixels clear\n", clear, f.size / 4);
    lpvc_frame_free(&f);
    lpvc_frame_desc bad = {.format = "png", .exposure = "bright"};
    assert_int_equal(lpvc_get_frame(c, &bad, &f), -1);
    assert_string_equal(lpvc_error_name(c), "BAD_FIELD");

    lpvc_frame_desc exr = {.format = "exr"};
    OK(c, lpvc_get_frame(c, &exr, &f));
    assert_true(f.size > 4);
    assert_memory_equal(f.data, "\x76\x2f\x31\x01", 4); /* OpenEXR magic */
    lpvc_frame_free(&f);
    OK(c, lpvc_bye(c));
    lpvc_close(c);
}

static void test_state_changes_bump_revision(void **state)
{
    (void)state;
    REQUIRE_DAEMON();
    lpvc *c = open_client();
    int64_t r0 = -1;
    float pos[3] = {0, 1.5f, 0}, col[3] = {1, 0.5f, 0.25f};
    lpvc_light l = {.id = "probe", .type = "point", .intensity = 3, .position = pos, .color = col};
    OK(c, lpvc_light_set(c, &l));
    r0 = lpvc_last_revision(c);
    assert_true(r0 >= 1);
    OK(c, lpvc_light_remove(c, "probe"));
    assert_true(lpvc_last_revision(c) > r0);
    r0 = lpvc_last_revision(c);
    lpvc_setting knobs[] = {{"iterations", 4}, {"occlusion", 0}};
    lpvc_config cfg = {.settings = knobs, .setting_count = 2};
    OK(c, lpvc_config_set(c, &cfg));
    assert_true(lpvc_last_revision(c) > r0);
    json_t *r = last_reply(c);
    json_t *eff = json_object_get(r, "config");
    assert_true(json_is_object(eff));
    assert_int_equal(json_integer_value(json_object_get(eff, "iterations")), 4);
    assert_true(json_is_false(json_object_get(eff, "occlusion")));
    json_decref(r);
    r0 = lpvc_last_revision(c);
    OK(c, lpvc_scene_update(c, "{\"materials\": [{\"material\": 0, \"base_color\": [0.5, 0.5, 0.5, 1]}]}"));
    assert_true(lpvc_last_revision(c) > r0);
    r0 = lpvc_last_revision(c);
    OK(c, lpvc_tick(c, NULL));
    assert_int_equal(lpvc_last_revision(c), r0); /* TICK reports the revision it reflects (R3.3) */
    char *st = NULL;
    OK(c, lpvc_stats(c, &st));
    json_t *s = json_loads(st, 0, NULL);
    assert_non_null(s);
    assert_true(json_is_object(s));
    assert_non_null(json_object_get(s, "ticks"));
    json_decref(s);
    free(st);
    OK(c, lpvc_bye(c));
    lpvc_close(c);
}

/* STATS' plan (the session's latest tick, R4.13): its counts and plan. */
static json_t *latest_tick(lpvc *c)
{
    char *st = NULL;
    OK(c, lpvc_stats(c, &st));
    json_t *s = json_loads(st, 0, NULL);
    free(st);
    assert_non_null(s);
    json_t *tick = json_incref(json_object_get(s, "plan"));
    json_decref(s);
    assert_true(json_is_object(tick));
    return tick;
}

static json_int_t tick_count(json_t *tick, const char *name)
{
    json_t *v = json_object_get(json_object_get(tick, "counts"), name);
    assert_true(json_is_integer(v));
    return json_integer_value(v);
}

/* A CONFIG recomputes only what its knobs touch (issue 11): the world's
 * engine (this session's alone) sends no geometry again, a shading knob
 * serves the cached volume, and a sampling knob re-samples the scene the
 * engine kept. */
static void test_config_recomputes_only_what_it_touches(void **state)
{
    (void)state;
    REQUIRE_DAEMON();
    lpvc *c = open_client();
    /* a setting no other test uses: this session's world is its own */
    OK(c, lpvc_config_json(c, "{\"damping\": 0.125}"));
    OK(c, lpvc_tick(c, NULL));
    json_t *t0 = latest_tick(c);
    const json_int_t uploads = tick_count(t0, "scene_uploads"), samplings = tick_count(t0, "scene_samplings");
    assert_true(uploads >= 1);

    OK(c, lpvc_config_json(c, "{\"damping\": 0.25, \"indirect_gain\": 2}"));
    OK(c, lpvc_tick(c, NULL));
    json_t *t1 = latest_tick(c);
    assert_int_equal(tick_count(t1, "scene_uploads"), uploads);
    assert_int_equal(tick_count(t1, "scene_samplings"), samplings);
    json_t *plan = json_object_get(t1, "plan");
    assert_true(json_is_false(json_object_get(plan, "recompute")));

    OK(c, lpvc_config_json(c, "{\"scene_surfel_count\": 4096}"));
    OK(c, lpvc_tick(c, NULL));
    json_t *t2 = latest_tick(c);
    assert_int_equal(tick_count(t2, "scene_uploads"), uploads);
    assert_int_equal(tick_count(t2, "scene_samplings"), samplings + 1);
    plan = json_object_get(t2, "plan");
    assert_true(json_is_true(json_object_get(plan, "recompute")));
    assert_string_equal(json_string_value(json_object_get(plan, "recompute_reason")),
                        "the settings changed (scene_surfel_count)");
    json_decref(t0);
    json_decref(t1);
    json_decref(t2);
    OK(c, lpvc_bye(c));
    lpvc_close(c);
}

/* Loads the shared Cornell box .glb when ../shared is there. */
static void test_load_glb(void **state)
{
    (void)state;
    REQUIRE_DAEMON();
    const char *shared = lpvt_shared_dir();
    if (!shared) {
        print_message("skipped: no ../shared (LPVD_SHARED_DIR)\n");
        skip();
    }
    char path[PATH_MAX];
    snprintf(path, sizeof path, "%s/scenes/cornell-box.glb", shared);
    FILE *f = fopen(path, "rb");
    if (!f) {
        print_message("skipped: no %s\n", path);
        skip();
    }
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fseek(f, 0, SEEK_SET);
    assert_true(size > 0);
    unsigned char *glb = malloc((size_t)size);
    assert_non_null(glb);
    assert_int_equal(fread(glb, 1, (size_t)size, f), (size_t)size);
    fclose(f);
    lpvc *c = open_client();
    OK(c, lpvc_scene_load_glb(c, glb, (size_t)size));
    free(glb);
    json_t *r = last_reply(c);
    json_t *scene = json_object_get(r, "scene");
    assert_true(json_integer_value(json_object_get(scene, "triangles")) > 0);
    assert_int_equal(json_array_size(json_object_get(scene, "bounds")), 6);
    json_decref(r);
    OK(c, lpvc_camera_set(c, &(lpvc_camera){.scene_camera = 1}));
    OK(c, lpvc_tick(c, NULL));
    OK(c, lpvc_bye(c));
    lpvc_close(c);
}

/* Volume stream with XOR deltas: every streamed volume, rebuilt by the
 * client, equals a fresh keyframe of the same tick bit for bit. */
static void test_stream_deltas(void **state)
{
    (void)state;
    REQUIRE_DAEMON();
    lpvc *c = open_client();
    lpvc_subscribe_desc sd = {.stream = LPVC_STREAM_VOLUME, .format = "fp16", .compression = "zstd", .delta = true};
    OK(c, lpvc_subscribe(c, &sd));
    int deltas = 0;
    for (int i = 0; i < 4; i++) {
        if (i == 2) {
            /* change the light so the volume changes between ticks */
            float pos[3] = {0.3f, 1.2f, 0.1f};
            lpvc_light l = {.id = "moving", .intensity = 2, .position = pos};
            OK(c, lpvc_light_set(c, &l));
        }
        int64_t tick = -1;
        OK(c, lpvc_tick(c, &tick));
        lpvc_message m;
        OK(c, lpvc_next_stream_message(c, &m, 120000));
        assert_int_equal(m.type, LPVC_MSG_VOLUME);
        /* R3.3: the stream volume of this tick (not an older one). */
        assert_int_equal(m.volume.tick, tick);
        assert_string_equal(m.volume.format, "fp16");
        if (!m.volume.keyframe) {
            deltas++;
            assert_true(m.volume.base_tick < m.volume.tick);
        }
        lpvc_volume key;
        lpvc_volume_desc d = {.format = "fp16", .compression = "none"};
        OK(c, lpvc_get_volume(c, &d, &key));
        assert_int_equal(key.tick, m.volume.tick);
        assert_int_equal(key.cells, m.volume.cells);
        assert_memory_equal(key.data, m.volume.data, key.cells * 12 * sizeof(float));
        lpvc_volume_free(&key);
        lpvc_message_free(&m);
    }
    /* Each volume was ACKed before the next TICK (R3.2 orders them), so the
     * server had an acknowledged base for ticks 2.. (R5.3). */
    assert_true(deltas >= 1);
    OK(c, lpvc_unsubscribe(c, LPVC_STREAM_VOLUME));
    /* Unsubscribed: a tick sends no volume. */
    OK(c, lpvc_tick(c, NULL));
    lpvc_message m;
    assert_int_equal(lpvc_next_stream_message(c, &m, 1000), -1);
    assert_int_equal(lpvc_error_code(c), LPVC_ERR_TIMEOUT);
    OK(c, lpvc_bye(c));
    lpvc_close(c);
}

/* Without ACK no delta (R5.3: only against an acknowledged tick); after a
 * manual ACK the next volume is a delta against exactly that tick. */
static void test_manual_ack(void **state)
{
    (void)state;
    REQUIRE_DAEMON();
    lpvc *c = open_client();
    lpvc_set_auto_ack(c, false);
    lpvc_subscribe_desc sd = {.stream = LPVC_STREAM_VOLUME, .format = "fp32", .compression = "zstd", .delta = true};
    OK(c, lpvc_subscribe(c, &sd));
    int64_t first = -1;
    for (int i = 0; i < 2; i++) {
        OK(c, lpvc_tick(c, NULL));
        lpvc_message m;
        OK(c, lpvc_next_stream_message(c, &m, 120000));
        assert_int_equal(m.type, LPVC_MSG_VOLUME);
        assert_true(m.volume.keyframe); /* nothing acknowledged yet */
        if (i == 0)
            first = m.volume.tick;
        lpvc_message_free(&m);
    }
    OK(c, lpvc_ack(c, first));
    OK(c, lpvc_tick(c, NULL));
    lpvc_message m;
    OK(c, lpvc_next_stream_message(c, &m, 120000));
    assert_int_equal(m.type, LPVC_MSG_VOLUME);
    assert_false(m.volume.keyframe);
    assert_int_equal(m.volume.base_tick, first);
    lpvc_volume key;
    OK(c, lpvc_get_volume(c, &(lpvc_volume_desc){.format = "fp32", .compression = "none"}, &key));
    assert_int_equal(key.tick, m.volume.tick);
    assert_memory_equal(key.data, m.volume.data, key.cells * 12 * sizeof(float));
    lpvc_volume_free(&key);
    lpvc_message_free(&m);
    OK(c, lpvc_bye(c));
    lpvc_close(c);
}

static void test_frame_stream(void **state)
{
    (void)state;
    REQUIRE_DAEMON();
    lpvc *c = open_client();
    float eye[3] = {0, 1, 3.9f}, target[3] = {0, 1, 0};
    OK(c, lpvc_camera_set(c, &(lpvc_camera){.eye = eye, .target = target, .width = 32, .height = 32}));
    lpvc_subscribe_desc sd = {.stream = LPVC_STREAM_FRAME, .format = "rgba8", .compression = "zstd"};
    OK(c, lpvc_subscribe(c, &sd));
    int64_t tick = -1;
    OK(c, lpvc_tick(c, &tick));
    lpvc_message m;
    OK(c, lpvc_next_stream_message(c, &m, 120000));
    assert_int_equal(m.type, LPVC_MSG_FRAME);
    assert_int_equal(m.frame.tick, tick);
    assert_int_equal(m.frame.size, (size_t)m.frame.width * m.frame.height * 4);
    lpvc_message_free(&m);
    OK(c, lpvc_unsubscribe(c, LPVC_STREAM_FRAME));
    OK(c, lpvc_bye(c));
    lpvc_close(c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_connect_refused),
        cmocka_unit_test(test_hello),
        cmocka_unit_test(test_knob_description),
        cmocka_unit_test(test_errors_keep_the_connection),
        cmocka_unit_test(test_tick_volume_query),
        cmocka_unit_test(test_octree_levels),
        cmocka_unit_test(test_iv_volume),
        cmocka_unit_test(test_probes_visibility),
        cmocka_unit_test(test_frames),
        cmocka_unit_test(test_state_changes_bump_revision),
        cmocka_unit_test(test_config_recomputes_only_what_it_touches),
        cmocka_unit_test(test_load_glb),
        cmocka_unit_test(test_stream_deltas),
        cmocka_unit_test(test_manual_ack),
        cmocka_unit_test(test_frame_stream),
    };
    return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
