/*
 * test_probes_gpu.c - the probes technique on the engine (GL path):
 *   - inside a closed box whose walls glow with radiance L (area lights
 *     off, so the probes see the emission), every probe's SH gives the
 *     irradiance pi L on every normal;
 *   - the update shaders agree with the CPU oracle (probes_update.c) on
 *     the same rays: the SH of a box with one brighter wall, the distance
 *     moments of every texel, probe by probe;
 *   - probes inside a solid block see back faces and are off, the others
 *     on, and the frame's light is finite and not negative;
 *   - a light that moves: the probes keep their history and follow it (the
 *     ticks until the light is within 10 % of the settled light's: the time
 *     to converge);
 *   - geometry that moves (the same triangles posed anew): the probes keep
 *     their history, update a budget, and settle where a fresh volume of
 *     the moved scene settles;
 *   - a camera that moves a cascade by whole cells: the probes that stay
 *     keep their light bit for bit at their new index, only the probes it
 *     brought in warm up, and their light is a fresh warmup's.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "engine.h"
#include "probes_bvh.h"
#include "probes_lookup.h"
#include "probes_rules.h"
#include "probes_update.h"
#include "scene.h"
#include "scene_build.h"
#include "sh.h"
#include "test_util.h"

/* A quad of half-sides |u|, |v| about centre c whose winding faces u x v. */
static void quad(lpv_scene *s, int m, const float c[3], const float u[3], const float v[3])
{
    float q[4][3];
    for (int i = 0; i < 3; ++i) {
        q[0][i] = c[i] - u[i] - v[i];
        q[1][i] = c[i] + u[i] - v[i];
        q[2][i] = c[i] + u[i] + v[i];
        q[3][i] = c[i] - u[i] + v[i];
    }
    assert_true(lpv_scene_add_quad(s, m, q, NULL) >= 0);
}

/* The box [-h, h]^3 with its faces' fronts inward; the +y face (the
 * ceiling) gets material `top`, the others `walls`. */
static void inward_box(lpv_scene *s, float h, int walls, int top)
{
    for (int a = 0; a < 3; ++a)
        for (int sign = -1; sign <= 1; sign += 2) {
            float c[3] = {0, 0, 0}, u[3] = {0, 0, 0}, v[3] = {0, 0, 0};
            c[a] = (float)sign * h;
            /* u x v = -sign e_a (inward): u = e_(a+1), v = e_(a+2) gives +e_a */
            u[(a + 1) % 3] = h;
            v[(a + 2) % 3] = (float)-sign * h;
            quad(s, (a == 1 && sign > 0) ? top : walls, c, u, v);
        }
}

static int glowing(lpv_scene *s, const char *name, float l, int double_sided)
{
    const float zero[3] = {0, 0, 0}, e[3] = {l, 0.5f * l, 0.25f * l};
    const int m = lpv_scene_add_material(s, name, zero, e);
    assert_true(m >= 0);
    s->materials[m].double_sided = double_sided;
    return m;
}

static lpv_settings probe_settings(int grid)
{
    lpv_settings st = {.technique = LPV_TECHNIQUE_ID_PROBES, .grid_dims = {grid, grid, grid}};
    st.area_lights = LPV_SWITCH_OFF;
    st.probes.warmup = 1;
    return st;
}

static void run(lpv_scene *scene, const lpv_settings *st)
{
    char err[1024] = "";
    if (lpv_engine_set_settings(lpvt_engine, st, err, sizeof err) != 0 ||
        lpv_engine_set_scene(lpvt_engine, scene, err, sizeof err) != 0 || lpv_engine_tick(lpvt_engine, err, sizeof err))
        fail_msg("%s", err);
}

/* Irradiance (rgb) from a probe's cell (the lookup's convention: cell^2 x
 * the SH by travel direction) on unit normal n. */
static void cell_irradiance(const lpv_cell *c, float cell, const float n[3], float e[3])
{
    float lobe[4];
    const float m[3] = {-n[0], -n[1], -n[2]};
    lpv_sh_cosine_lobe(m, lobe);
    e[0] = lpv_sh_dot(c->r, lobe) / (cell * cell);
    e[1] = lpv_sh_dot(c->g, lobe) / (cell * cell);
    e[2] = lpv_sh_dot(c->b, lobe) / (cell * cell);
}

static void test_glowing_box_gives_pi_l(void **state)
{
    (void)state;
    lpv_scene scene = {0};
    const int m = glowing(&scene, "glow", 0.8f, 0);
    inward_box(&scene, 1.0f, m, m);
    lpv_scene_compute_bounds(&scene);
    const lpv_settings st = probe_settings(4);
    run(&scene, &st);
    const lpv_volume_desc *d = &lpv_engine_last_stats(lpvt_engine)->volume;
    assert_string_equal(d->technique, LPV_TECHNIQUE_PROBES);
    assert_int_equal(d->levels, 1);
    const float cell = d->level[0].cell_size;
    lpv_cell cells[64];
    assert_int_equal(lpv_engine_read_grid(lpvt_engine, LPV_GRID_ACCUMULATED, cells, 64), 64);
    static const float axes[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (int i = 0; i < 64; ++i)
        for (int a = 0; a < 6; ++a) {
            float e[3];
            cell_irradiance(&cells[i], cell, axes[a], e);
            for (int c = 0; c < 3; ++c) {
                const float want = (float)LPV_PI * 0.8f * (c == 0 ? 1.0f : c == 1 ? 0.5f : 0.25f);
                if (!(fabsf(e[c] - want) <= 0.01f * want))
                    fail_msg("probe %d normal %d channel %d: %g W/m^2, want %g", i, a, c, (double)e[c], (double)want);
            }
        }
    assert_int_equal((int)lpv_stats_get(lpv_engine_last_stats(lpvt_engine), "probes_off")->v[0], 0);
    lpv_scene_free(&scene);
}

typedef struct {
    const lpv_scene *scene;
    const int *tri_material;
} shade_ctx;

static void shade_emission(void *ctx, uint32_t tri, const float p[3], const float d[3], float t, float l[3])
{
    (void)p, (void)d, (void)t;
    const shade_ctx *c = ctx;
    memcpy(l, c->scene->materials[c->tri_material[tri]].emission, 3 * sizeof *l);
}

static void test_update_matches_cpu_oracle(void **state)
{
    (void)state;
    lpv_scene scene = {0};
    const int walls = glowing(&scene, "walls", 0.3f, 1), top = glowing(&scene, "top", 2.0f, 1);
    inward_box(&scene, 1.0f, walls, top);
    lpv_scene_compute_bounds(&scene);
    lpv_settings st = probe_settings(3);
    st.probes.rays = 96;
    st.probes.oct = 6;
    run(&scene, &st);
    const lpv_volume_desc *d = &lpv_engine_last_stats(lpvt_engine)->volume;
    const lpv_grid *g = &d->level[0];
    const size_t n = 27;
    lpv_cell cells[27];
    assert_int_equal(lpv_engine_read_grid(lpvt_engine, LPV_GRID_ACCUMULATED, cells, n), n);
    const size_t texels = 36;
    assert_int_equal(d->visibility_side, 6);
    const size_t per = lpv_probes_record_values(d->irradiance_side, d->visibility_side),
                 at = lpv_probes_record_distance_at(d->irradiance_side);
    assert_int_equal(per, 4 + 3 * LPV_PROBES_IRR_OCT * LPV_PROBES_IRR_OCT + 2 * texels);
    float *records = malloc(n * per * sizeof *records), *moments = malloc(n * texels * 2 * sizeof *moments);
    assert_int_equal(lpv_engine_read_visibility(lpvt_engine, records, n * per), n * per);
    for (size_t p = 0; p < n; ++p) {
        memcpy(moments + p * texels * 2, records + p * per + at, texels * 2 * sizeof *moments);
        assert_true(records[p * per + LPV_PROBES_RECORD_ACTIVE] == 1.0f); /* an open box: every probe on */
    }
    free(records);

    /* the same rays on the CPU: the triangles in draw order, each quad two */
    float pos[3 * 24];
    for (uint32_t v = 0; v < scene.vertex_count; ++v)
        memcpy(pos + 3 * v, scene.vertices[v].position, sizeof(float) * 3);
    int tri_material[12];
    for (uint32_t k = 0; k < scene.draw_count; ++k)
        for (uint32_t i = 0; i < scene.draws[k].index_count / 3; ++i)
            tri_material[scene.draws[k].first_index / 3 + i] = scene.draws[k].material;
    lpv_probes_bvh bvh;
    char err[256];
    assert_int_equal(lpv_probes_bvh_build(&bvh, pos, scene.vertex_count, scene.indices, scene.index_count / 3, err,
                                          sizeof err),
                     0);
    float positions[3 * 27];
    for (size_t p = 0; p < n; ++p) {
        const int c[3] = {(int)(p % 3), (int)(p / 3 % 3), (int)(p / 9)};
        for (int i = 0; i < 3; ++i)
            positions[3 * p + i] = ((float)c[i] + 0.5f + d->origin_cells[0][i]) * g->cell_size;
    }
    shade_ctx ctx = {&scene, tri_material};
    lpv_probe_result res[27];
    float cpu_moments[27][72];
    for (size_t p = 0; p < n; ++p)
        res[p].moments = cpu_moments[p];
    lpv_probes_update_desc u = {.bvh = &bvh, .positions = positions, .probe_count = n, .rays = 96,
                                .tick = 0, .seed = LPV_PROBES_SEED, .max_distance = 100.0f, .oct_size = 6,
                                .sharpness = LPV_PROBES_SHARPNESS, .shade = shade_emission, .ctx = &ctx};
    assert_int_equal(lpv_probes_update_cpu(&u, res), 0);
    /* one ray's worth of a coefficient: a ray at a box edge may land on the
     * other wall on one side only */
    const float one_ray = 4.0f * (float)LPV_PI / 96.0f * 2.0f * 0.4886f;
    const float c2 = g->cell_size * g->cell_size;
    double worst = 0.0;
    for (size_t p = 0; p < n; ++p)
        for (int k = 0; k < 4; ++k) {
            const float sign = k == 0 ? 1.0f : -1.0f; /* arrival vs travel direction */
            const float diff[3] = {cells[p].r[k] / c2 - sign * res[p].sh[0][k], cells[p].g[k] / c2 - sign * res[p].sh[1][k],
                                   cells[p].b[k] / c2 - sign * res[p].sh[2][k]};
            for (int c = 0; c < 3; ++c) {
                if (!(fabsf(diff[c]) <= one_ray))
                    fail_msg("probe %zu coefficient %d channel %d: GPU %g, CPU %g", p, k, c,
                             (double)((c == 0 ? cells[p].r : c == 1 ? cells[p].g : cells[p].b)[k] / c2),
                             (double)(sign * res[p].sh[c][k]));
                worst = fmax(worst, fabs(diff[c]));
            }
        }
    printf("SH: worst |GPU - CPU| %.3g (one ray %.3g)\n", worst, (double)one_ray);
    /* the moments: the GPU clamps hits at LPV_PROBES_MOMENT_CELLS cells, the
     * CPU stops its rays there (a miss counts that far): the same numbers */
    const float mmax = LPV_PROBES_MOMENT_CELLS * g->cell_size;
    u.max_distance = mmax;
    u.shade = NULL;
    assert_int_equal(lpv_probes_update_cpu(&u, res), 0);
    size_t off = 0;
    for (size_t p = 0; p < n; ++p)
        for (size_t k = 0; k < 2 * texels; ++k) {
            const float gpu = moments[p * 2 * texels + k], cpu = cpu_moments[p][k];
            const float scale = (k % 2) ? mmax * mmax : mmax;
            if (!(fabsf(gpu - cpu) <= 2e-3f * scale))
                ++off;
        }
    printf("moments: %zu of %zu differ by more than 0.2 %% of the clamp\n", off, n * 2 * texels);
    assert_true(off <= n * 2 * texels / 100);
    lpv_probes_bvh_free(&bvh);
    free(moments);
    lpv_scene_free(&scene);
}

/* A room [-h, h]^3 of one-sided grey walls facing in (a back face is a
 * back face); returns its material, for more geometry. */
static int grey_room(lpv_scene *scene, float h)
{
    const float grey[3] = {0.5f, 0.5f, 0.5f};
    const int m = lpv_scene_add_material(scene, "grey", grey, NULL);
    scene->materials[m].double_sided = 0;
    inward_box(scene, h, m, m);
    return m;
}

static void test_probes_in_a_block_are_off(void **state)
{
    (void)state;
    lpv_scene scene = {0};
    const int m = grey_room(&scene, 2.0f);
    /* a solid block (outward faces, one-sided) over the lower middle */
    assert_true(lpv_scene_add_box(&scene, m, (const float[3]){-1.0f, -2.0f, -1.0f}, (const float[3]){1.0f, 0.0f, 1.0f}) >= 0);
    lpv_scene_add_point_light(&scene, (const float[3]){0.0f, 1.5f, 0.0f}, 20.0f);
    lpv_scene_compute_bounds(&scene);
    lpv_settings st = probe_settings(4);
    st.area_lights = LPV_SWITCH_DEFAULT;
    run(&scene, &st);
    /* probe centres at -1.5, -0.5, 0.5, 1.5 per axis: inside the block are
     * x, z in {-0.5, 0.5} and y in {-1.5, -0.5}: 8 */
    const lpv_engine_stats *s = lpv_engine_last_stats(lpvt_engine);
    assert_int_equal((int)lpv_stats_get(s, "probes_off")->v[0], 8);
    lpv_cell cells[64];
    assert_int_equal(lpv_engine_read_grid(lpvt_engine, LPV_GRID_ACCUMULATED, cells, 64), 64);
    for (int i = 0; i < 64; ++i)
        for (int k = 0; k < 4; ++k)
            assert_true(isfinite(cells[i].r[k]) && isfinite(cells[i].g[k]) && isfinite(cells[i].b[k]));
    lpv_scene_free(&scene);
}

/* Relocation: probes in a solid slab whose top lies within their cell
 * move out through it on the first warmup pass and are on; those deeper
 * stay off; no other probe is near enough a surface to move. */
static void test_probes_relocate(void **state)
{
    (void)state;
    lpv_scene scene = {0};
    const int m = grey_room(&scene, 2.0f);
    /* probe centres at -1.5, -0.5, 0.5, 1.5 (cells of 1 m): the slab's top
     * at y = -0.2 is 0.3 m above the probes at y = -0.5 (moved up to
     * -0.5 + 0.3 + 0.1 = -0.1) and 1.3 m above those at y = -1.5 (too far:
     * off); x, z in (-1, 1): the 4 middle columns */
    assert_true(lpv_scene_add_box(&scene, m, (const float[3]){-1.0f, -2.0f, -1.0f}, (const float[3]){1.0f, -0.2f, 1.0f}) >= 0);
    lpv_scene_add_point_light(&scene, (const float[3]){0.0f, 1.5f, 0.0f}, 20.0f);
    lpv_scene_compute_bounds(&scene);
    lpv_settings st = probe_settings(4);
    st.area_lights = LPV_SWITCH_DEFAULT;
    st.probes.warmup = 2;
    /* a fresh volume: the last test's scene has the same triangles, posed
     * otherwise, so its probes would keep their light and positions */
    lpv_engine_forget(lpvt_engine);
    run(&scene, &st);
    const lpv_engine_stats *s = lpv_engine_last_stats(lpvt_engine);
    /* the 8 in the slab: 4 moved out and on, 4 off; none other is nearer
     * than 0.2 cells to a surface */
    assert_int_equal((int)lpv_stats_get(s, "probes_off")->v[0], 4);
    assert_int_equal((int)lpv_stats_get(s, "probes_moved")->v[0], 4);
    lpv_scene_free(&scene);
}

/* Geometry posed anew over probes that hold light: the slab of
 * test_probes_relocate rises from the floor (the same triangles) through
 * the probes' bottom layers. The probes keep their light, and the sweep
 * after the move relocates as a warmup's pass 0 does: after the sweep
 * after it, the same 4 moved out and 4 off as a fresh volume of the risen
 * slab. */
static void test_probes_relocate_after_geometry_moves(void **state)
{
    (void)state;
    lpv_scene low = {0}, high = {0};
    for (int i = 0; i < 2; ++i) {
        lpv_scene *sc = i ? &high : &low;
        const int m = grey_room(sc, 2.0f);
        assert_true(lpv_scene_add_box(sc, m, (const float[3]){-1.0f, -2.0f, -1.0f},
                                      (const float[3]){1.0f, i ? -0.2f : -1.9f, 1.0f}) >= 0);
        lpv_scene_add_point_light(sc, (const float[3]){0.0f, 1.5f, 0.0f}, 20.0f);
        lpv_scene_compute_bounds(sc);
    }
    lpv_settings st = probe_settings(4);
    st.area_lights = LPV_SWITCH_DEFAULT;
    st.probes.warmup = 2;
    st.probes.budget = 16; /* a sweep: 4 ticks */
    lpv_engine_forget(lpvt_engine);
    run(&low, &st);
    const lpv_engine_stats *s = lpv_engine_last_stats(lpvt_engine);
    assert_int_equal((int)lpv_stats_get(s, "probes_off")->v[0], 0); /* 0.4 m above the slab: where they are */
    assert_int_equal((int)lpv_stats_get(s, "probes_moved")->v[0], 0);
    char err[512];
    assert_int_equal(lpv_engine_set_scene(lpvt_engine, &high, err, sizeof err), 0);
    /* a sweep relocates; the next traces from where the probes moved (a
     * moved probe is off until then: its last rays left from inside) */
    for (int t = 0; t < 8; ++t) {
        assert_int_equal(lpv_engine_tick(lpvt_engine, err, sizeof err), 0);
        assert_int_equal((int)lpv_stats_get(lpv_engine_last_stats(lpvt_engine), "probes_updated")->v[0], 16);
    }
    s = lpv_engine_last_stats(lpvt_engine);
    assert_int_equal((int)lpv_stats_get(s, "probes_off")->v[0], 4);
    assert_int_equal((int)lpv_stats_get(s, "probes_moved")->v[0], 4);
    lpv_scene_free(&low);
    lpv_scene_free(&high);
}

/* The lookup (SPEC R5.15): the server's (probes_lookup.glsl, through
 * lpv_engine_irradiance) equals the CPU oracle's on the read-back records
 * (probes_lookup.c, the clients' code) at points on every surface of a
 * room with a slab, whose probes are moved, off or near walls; and the
 * distance maps matter: without them (every probe sees every point) the
 * answer differs at many of those points. */
static void test_lookup_matches_cpu_oracle(void **state)
{
    (void)state;
    lpv_scene scene = {0};
    const int m = grey_room(&scene, 2.0f);
    assert_true(lpv_scene_add_box(&scene, m, (const float[3]){-1.0f, -2.0f, -1.0f}, (const float[3]){1.0f, -0.2f, 1.0f}) >= 0);
    /* a thin partition: the far side of x = 1.3 is lit only around it */
    quad(&scene, m, (const float[3]){1.3f, 0.0f, -0.5f}, (const float[3]){0, 2.0f, 0}, (const float[3]){0, 0, 1.5f});
    quad(&scene, m, (const float[3]){1.3f, 0.0f, -0.5f}, (const float[3]){0, 0, 1.5f}, (const float[3]){0, 2.0f, 0});
    lpv_scene_add_point_light(&scene, (const float[3]){-0.5f, 1.5f, 0.5f}, 20.0f);
    lpv_scene_compute_bounds(&scene);
    lpv_settings st = probe_settings(5);
    st.area_lights = LPV_SWITCH_DEFAULT;
    st.probes.warmup = 2;
    run(&scene, &st);
    const lpv_volume_desc *d = &lpv_engine_last_stats(lpvt_engine)->volume;
    const size_t per = lpv_probes_record_values(d->irradiance_side, d->visibility_side);
    size_t probes = 0;
    for (int k = 0; k < d->levels; ++k)
        probes += (size_t)d->level[k].dims[0] * d->level[k].dims[1] * d->level[k].dims[2];
    float *rec = malloc(probes * per * sizeof *rec), *blind = malloc(probes * per * sizeof *blind);
    assert_int_equal(lpv_engine_read_visibility(lpvt_engine, rec, probes * per), probes * per);
    lpv_probes_field f = {.levels = d->levels, .irradiance_side = d->irradiance_side,
                          .distance_side = d->visibility_side, .bias_cells = d->visibility_bias_cells};
    size_t first = 0;
    for (int k = 0; k < d->levels; ++k) {
        const lpv_grid *g = &d->level[k];
        lpv_probes_level *l = &f.level[k];
        memcpy(l->dims, g->dims, sizeof l->dims);
        for (int a = 0; a < 3; ++a)
            l->origin[a] = d->origin_cells[k][a] * g->cell_size;
        l->cell_size = g->cell_size;
        l->records = rec + first * per;
        first += (size_t)g->dims[0] * g->dims[1] * g->dims[2];
    }
    lpv_probes_field open = f;
    memcpy(blind, rec, probes * per * sizeof *rec);
    const size_t at = lpv_probes_record_distance_at(d->irradiance_side);
    for (size_t i = 0; i < probes; ++i)
        for (size_t t = at; t < per; t += 2) {
            blind[i * per + t] = 1e6f;
            blind[i * per + t + 1] = 1e12f;
        }
    for (int k = 0; k < d->levels; ++k)
        open.level[k].records = blind + (f.level[k].records - rec);

    /* points on the walls, the slab's faces and both sides of the partition */
    enum { N = 600 };
    float *p = malloc(N * 3 * sizeof *p), *n = malloc(N * 3 * sizeof *n), *gpu = malloc(N * 3 * sizeof *gpu);
    uint32_t h = 12345u;
    for (int i = 0; i < N; ++i) {
        float u[2];
        for (int j = 0; j < 2; ++j) {
            h = h * 1664525u + 1013904223u;
            u[j] = (float)(h >> 8) / 16777216.0f * 2.0f - 1.0f;
        }
        float *q = p + 3 * i, *nn = n + 3 * i;
        const int kind = i % 6;
        if (kind < 3) { /* a room wall, facing in */
            const int a = (i / 6) % 3, sign = (i / 18) % 2 ? 1 : -1;
            q[a] = 1.99f * (float)sign;
            q[(a + 1) % 3] = 1.9f * u[0];
            q[(a + 2) % 3] = 1.9f * u[1];
            nn[0] = nn[1] = nn[2] = 0.0f;
            nn[a] = (float)-sign;
        } else if (kind == 3) { /* the slab's top */
            q[0] = 0.95f * u[0], q[1] = -0.19f, q[2] = 0.95f * u[1];
            nn[0] = 0, nn[1] = 1, nn[2] = 0;
        } else { /* the partition, one side or the other */
            const float side = kind == 4 ? -1.0f : 1.0f;
            q[0] = 1.3f + 0.01f * side, q[1] = 1.9f * u[0], q[2] = -0.5f + 1.45f * u[1];
            nn[0] = side, nn[1] = 0, nn[2] = 0;
        }
    }
    char err[256];
    assert_int_equal(lpv_engine_irradiance(lpvt_engine, p, n, N, gpu, err, sizeof err), 0);
    float emax = 0.0f;
    for (int i = 0; i < 3 * N; ++i)
        emax = fmaxf(emax, gpu[i]);
    assert_true(emax > 0.0f);
    int off = 0, seen_changes = 0;
    double worst = 0.0;
    for (int i = 0; i < N; ++i) {
        float e[3], o[3];
        assert_int_equal(lpv_probes_irradiance(&f, p + 3 * i, n + 3 * i, e), 0);
        assert_int_equal(lpv_probes_irradiance(&open, p + 3 * i, n + 3 * i, o), 0);
        double diff = 0.0, change = 0.0;
        for (int c = 0; c < 3; ++c) {
            diff = fmax(diff, fabs(e[c] - gpu[3 * i + c]) / emax);
            change = fmax(change, fabs(o[c] - e[c]) / emax);
        }
        worst = fmax(worst, diff);
        off += diff > 1e-4;
        seen_changes += change > 0.01;
    }
    printf("lookup: %d of %d points differ from the oracle by more than 1e-4 of the brightest (worst %.3g); "
           "the distance maps change %d by more than 1 %%\n", off, N, worst, seen_changes);
    assert_true(off <= N / 50); /* the thresholds, where float rounding may fall either way */
    assert_true(seen_changes >= N / 20);
    free(p);
    free(n);
    free(gpu);
    free(rec);
    free(blind);
    lpv_scene_free(&scene);
}

/* A room lit by a point light at `at`: one-sided grey walls facing in. */
static void lit_room(lpv_scene *scene, const float at[3])
{
    grey_room(scene, 2.0f);
    lpv_scene_add_point_light(scene, at, 40.0f);
    lpv_scene_compute_bounds(scene);
}

/* Irradiance at points on the room's walls and floor, facing in. */
static void room_irradiance(float rgb[3 * 6])
{
    static const float p[6][3] = {{0, -1.95f, 0}, {1.95f, 0, 0}, {-1.95f, 0, 0}, {0, 0, 1.95f}, {0, 0, -1.95f}, {0, 1.95f, 0}};
    static const float n[6][3] = {{0, 1, 0}, {-1, 0, 0}, {1, 0, 0}, {0, 0, -1}, {0, 0, 1}, {0, -1, 0}};
    char err[256];
    assert_int_equal(lpv_engine_irradiance(lpvt_engine, &p[0][0], &n[0][0], 6, rgb, err, sizeof err), 0);
}

/* Ticks until the plan stops the probes ("settled"), at most `max`. */
static int settle(int max)
{
    char err[512];
    int n = 0;
    for (; n < max; ++n) {
        assert_int_equal(lpv_engine_tick(lpvt_engine, err, sizeof err), 0);
        if (!lpv_engine_last_plan(lpvt_engine)->pass[LPV_PASS_PROBES].run)
            break;
    }
    return n;
}

/* A light that moves: the probes keep their history (only the lights
 * changed) and follow it; the ticks until every point is within 10 % of the
 * settled light is the time to converge. The settled light, not a fresh
 * volume's: the feedback of every update adds the bounces past the
 * warmup's. 10 %: the settled light itself wanders by 3-7 % at these
 * points (64 rays a probe, the hysteresis keeping a tenth of each update). */
static void test_probes_follow_a_moved_light(void **state)
{
    (void)state;
    const float a[3] = {-1.7f, -1.5f, -1.7f}, b[3] = {1.7f, 1.5f, 1.7f};
    lpv_settings st = probe_settings(4);
    st.area_lights = LPV_SWITCH_DEFAULT;
    st.probes.warmup = 4;
    st.probes.budget = 16; /* 4 ticks a sweep over the 64 probes */
    lpv_scene at_b = {0}, at_a = {0}, back = {0};
    lit_room(&at_b, b);
    run(&at_b, &st); /* a new scene: a fresh volume, every probe 4 passes */
    const int sweeps = lpv_probes_settle_sweeps(0.9f, 0); /* after a warmup */
    assert_int_equal(sweeps, 44);
    assert_int_equal(lpv_probes_settle_sweeps(0.9f, 1), 32); /* after a change: the ramp forgets faster */
    const int first = settle(4 * sweeps + 8);
    assert_int_equal(first, 4 * sweeps); /* then the plan stops the probes */
    /* and the cached tick's stats say nothing ran (not the last sweep's 16) */
    const lpv_engine_stats *cached = lpv_engine_last_stats(lpvt_engine);
    assert_int_equal(cached->stage_count, 0);
    assert_int_equal((int)lpv_stats_get(cached, "probes_updated")->v[0], 0);
    assert_int_equal((int)lpv_stats_get(cached, "probes_rays")->v[0], 0);
    assert_float_equal(cached->cell_steps, 0.0, 0.0);
    assert_int_equal((int)lpv_stats_get(cached, "probes_sweeps")->v[0], sweeps);
    float want[18], got[18];
    room_irradiance(want);
    lit_room(&at_a, a);
    char err[512];
    assert_int_equal(lpv_engine_set_scene(lpvt_engine, &at_a, err, sizeof err), 0);
    settle(4 * sweeps + 8);
    assert_false(lpv_engine_last_plan(lpvt_engine)->pass[LPV_PASS_PROBES].run); /* settled */
    room_irradiance(got);
    double far = 0.0; /* the light moved away: the points see another light */
    for (int k = 0; k < 18; ++k)
        far = fmax(far, fabs(got[k] - want[k]) / fmax(want[k], 1e-6));
    printf("light moved: the points' light differs by up to %.0f %%\n", 100.0 * far);
    assert_true(far > 0.2);
    lit_room(&back, b);
    assert_int_equal(lpv_engine_set_scene(lpvt_engine, &back, err, sizeof err), 0);
    int ticks = 0;
    double worst = 1e30;
    for (; ticks < 4 * sweeps && worst > 0.1; ++ticks) {
        assert_int_equal(lpv_engine_tick(lpvt_engine, err, sizeof err), 0);
        assert_int_equal((int)lpv_stats_get(lpv_engine_last_stats(lpvt_engine), "probes_updated")->v[0], 16);
        room_irradiance(got);
        worst = 0.0;
        for (int k = 0; k < 18; ++k) {
            assert_true(isfinite(got[k]) && got[k] >= 0.0f);
            worst = fmax(worst, fabs(got[k] - want[k]) / fmax(want[k], 1e-6));
        }
    }
    printf("moved back: within 10 %% of the settled light after %d ticks (%.1f sweeps; budget 16 of 64 probes, "
           "hysteresis 0.9)\n", ticks, ticks / 4.0);
    assert_true(worst <= 0.1);
    lpv_scene_free(&at_b);
    lpv_scene_free(&at_a);
    lpv_scene_free(&back);
}

/* lpv_engine_forget: after ticks that carried light forward, the next tick
 * is the first tick's again, bit for bit (a batch's items must not depend
 * on the items before them), and says why it ran. */
static void test_forget_gives_a_fresh_tick(void **state)
{
    (void)state;
    const float b[3] = {1.5f, 1.3f, 1.5f};
    lpv_settings st = probe_settings(4);
    st.probes.warmup = 4;
    st.probes.budget = 16;
    lpv_scene room = {0};
    grey_room(&room, 1.8f); /* not the last test's room: a new scene, so the first tick is a fresh one */
    lpv_scene_add_point_light(&room, b, 40.0f);
    lpv_scene_compute_bounds(&room);
    run(&room, &st);
    assert_non_null(strstr(lpv_engine_last_plan(lpvt_engine)->pass[LPV_PASS_PROBES].reason, "warmup passes"));
    lpv_cell first[64], later[64];
    assert_int_equal(lpv_engine_read_grid(lpvt_engine, LPV_GRID_ACCUMULATED, first, 64), 64);
    char err[512];
    for (int i = 0; i < 8; ++i)
        assert_int_equal(lpv_engine_tick(lpvt_engine, err, sizeof err), 0);
    assert_int_equal(lpv_engine_read_grid(lpvt_engine, LPV_GRID_ACCUMULATED, later, 64), 64);
    assert_memory_not_equal(first, later, sizeof first); /* the history changed the light */
    lpv_engine_forget(lpvt_engine);
    assert_int_equal(lpv_engine_tick(lpvt_engine, err, sizeof err), 0);
    const lpv_plan *p = lpv_engine_last_plan(lpvt_engine);
    assert_true(p->pass[LPV_PASS_PROBES].run);
    assert_non_null(strstr(p->pass[LPV_PASS_PROBES].reason, "every probe, warmup passes"));
    assert_int_equal(lpv_engine_read_grid(lpvt_engine, LPV_GRID_ACCUMULATED, later, 64), 64);
    assert_memory_equal(first, later, sizeof first);
    lpv_scene_free(&room);
}

/* The grey room with a block (0.5 x 1 x 0.5 m, clear of every probe
 * centre) standing at x = z = at, lit from above. */
static void room_with_block(lpv_scene *scene, float at)
{
    const int m = grey_room(scene, 2.0f);
    assert_true(lpv_scene_add_box(scene, m, (const float[3]){at - 0.25f, -2.0f, at - 0.25f},
                                  (const float[3]){at + 0.25f, -1.0f, at + 0.25f}) >= 0);
    lpv_scene_add_point_light(scene, (const float[3]){0.2f, 1.5f, 0.1f}, 40.0f);
    lpv_scene_compute_bounds(scene);
}

/* Geometry that moves: the same triangles posed anew keep the probes'
 * light (a budget of probes a tick, not a warmup of every probe), which
 * follows the change as it follows a moved light and settles where a fresh
 * volume of the moved scene settles (within the settled light's own noise,
 * as test_probes_follow_a_moved_light). */
static void test_probes_follow_moved_geometry(void **state)
{
    (void)state;
    lpv_settings st = probe_settings(4);
    st.area_lights = LPV_SWITCH_DEFAULT;
    st.probes.warmup = 4;
    st.probes.budget = 16;
    lpv_scene before = {0}, after = {0};
    room_with_block(&before, -1.0f);
    room_with_block(&after, 1.0f);
    run(&before, &st);
    settle(4 * 44 + 8);
    char err[512];
    assert_int_equal(lpv_engine_set_scene(lpvt_engine, &after, err, sizeof err), 0);
    assert_int_equal(lpv_engine_tick(lpvt_engine, err, sizeof err), 0);
    const lpv_plan *p = lpv_engine_last_plan(lpvt_engine);
    assert_true(p->light_stale);
    assert_non_null(strstr(p->pass[LPV_PASS_PROBES].reason, "a budget of probes"));
    assert_int_equal((int)lpv_stats_get(lpv_engine_last_stats(lpvt_engine), "probes_updated")->v[0], 16);
    settle(4 * 44 + 8);
    assert_false(lpv_engine_last_plan(lpvt_engine)->pass[LPV_PASS_PROBES].run); /* settled */
    float got[18], want[18];
    room_irradiance(got);
    lpv_engine_forget(lpvt_engine); /* the moved scene afresh */
    settle(4 * 44 + 8);
    room_irradiance(want);
    double worst = 0.0;
    for (int k = 0; k < 18; ++k) {
        assert_true(isfinite(got[k]) && got[k] >= 0.0f);
        worst = fmax(worst, fabs(got[k] - want[k]) / fmax(want[k], 1e-6));
    }
    printf("moved geometry: settled within %.1f %% of a fresh volume's settled light\n", 100.0 * worst);
    assert_true(worst <= 0.1);
    lpv_scene_free(&before);
    lpv_scene_free(&after);
}

/* The GPU ms of the tick's probes passes (printed, never asserted). */
static double probes_ms(const lpv_engine_stats *s)
{
    double ms = 0.0;
    for (int i = 0; i < s->stage_count; ++i)
        ms += strncmp(s->stages[i].name, "probes", 6) == 0 ? s->stages[i].gpu_ms : 0.0;
    return ms;
}

/* A camera-following cascade that moves by whole cells (probes_scroll.comp):
 * the probes whose cells it still holds keep their light, distances and
 * state exactly, moved to their new index; only the probes it brought in
 * trace rays (a slab, warmup passes, no round robin: the light did not
 * change), and they come out lit like a fresh warmup's probes there. */
static void test_probes_scroll_with_the_camera(void **state)
{
    (void)state;
    enum { N = 8, CASCADES = 2, PROBES = CASCADES * N * N * N };
    const float light[3] = {0.5f, 3.0f, 0.3f};
    lpv_settings st = probe_settings(N);
    st.area_lights = LPV_SWITCH_DEFAULT;
    st.probes.warmup = 4;
    st.probes.budget = 128;
    st.lpv.cascades = CASCADES;
    st.lpv.cascade_size = 4.0f; /* cascade 0: 0.5 m cells, following the camera in the 8 m room */
    lpv_scene room = {0};
    grey_room(&room, 4.0f);
    lpv_scene_add_point_light(&room, light, 400.0f);
    lpv_scene_compute_bounds(&room);
    lpv_view view = {.eye = {-1.0f, 0.0f, 0.0f}, .forward = {1, 0, 0}, .up = {0, 1, 0}, .yfov = 1.0f, .width = 16,
                     .height = 16};
    char err[512];
    assert_int_equal(lpv_engine_set_view(lpvt_engine, &view, err, sizeof err), 0);
    run(&room, &st);
    for (int i = 0; i < 6; ++i) /* some history past the warmup */
        assert_int_equal(lpv_engine_tick(lpvt_engine, err, sizeof err), 0);
    lpv_volume_desc was = lpv_engine_last_stats(lpvt_engine)->volume;
    assert_int_equal(was.levels, CASCADES);
    static lpv_cell before[PROBES], after[PROBES], fresh[PROBES];
    assert_int_equal(lpv_engine_read_grid(lpvt_engine, LPV_GRID_ACCUMULATED, before, PROBES), PROBES);

    view.eye[0] += 2.2f * was.level[0].cell_size; /* two cells and a bit */
    assert_int_equal(lpv_engine_set_view(lpvt_engine, &view, err, sizeof err), 0);
    assert_int_equal(lpv_engine_tick(lpvt_engine, err, sizeof err), 0);
    assert_non_null(strstr(lpv_engine_last_plan(lpvt_engine)->pass[LPV_PASS_PROBES].reason,
                            "the probes the cascades' move brings in"));
    const lpv_volume_desc now = lpv_engine_last_stats(lpvt_engine)->volume;
    int shift[CASCADES][3], brought = 0;
    for (int k = 0; k < CASCADES; ++k) {
        assert_float_equal(now.level[k].cell_size, was.level[k].cell_size, 0.0f);
        for (int i = 0; i < 3; ++i)
            shift[k][i] = (int)(now.origin_cells[k][i] - was.origin_cells[k][i]);
    }
    assert_int_equal(shift[0][0], 2); /* the fine cascade followed the camera two cells; the coarse one spans the room */
    assert_int_equal(shift[0][1] | shift[0][2] | shift[1][0] | shift[1][1] | shift[1][2], 0);
    assert_int_equal(lpv_engine_read_grid(lpvt_engine, LPV_GRID_ACCUMULATED, after, PROBES), PROBES);
    size_t kept_same = 0;
    for (int k = 0; k < CASCADES; ++k)
        for (int z = 0; z < N; ++z)
            for (int y = 0; y < N; ++y)
                for (int x = 0; x < N; ++x) {
                    const int p = k * N * N * N + x + N * (y + N * z), ox = x + shift[k][0];
                    if (ox >= N) {
                        ++brought;
                        assert_true(after[p].r[0] > 0.0f && isfinite(after[p].r[0])); /* warmed up: lit */
                        continue;
                    }
                    kept_same += memcmp(&after[p], &before[p + shift[k][0]], sizeof after[p]) == 0;
                }
    assert_int_equal(brought, 2 * N * N);
    assert_int_equal(kept_same, PROBES - brought); /* bit for bit, at the new index */
    const lpv_engine_stats *s = lpv_engine_last_stats(lpvt_engine);
    const double scroll_ms = probes_ms(s);
    assert_int_equal((int)lpv_stats_get(s, "probes_scrolled_in")->v[0], brought);
    assert_int_equal((int)lpv_stats_get(s, "probes_updated")->v[0], 4 * brought); /* 4 warmup passes, nothing else */

    /* then the slab averages more passes alone, a budget (here all 128) a
     * tick, until it weighs as many as the settled probes' blend: 3 of the
     * warmup's averaged, 16 more at hysteresis 0.9 */
    assert_int_equal(lpv_probes_refine_passes(0.9f, 4), 19);
    for (int n = 3; n < 19; ++n) {
        assert_int_equal(lpv_engine_tick(lpvt_engine, err, sizeof err), 0);
        char want[96];
        snprintf(want, sizeof want, "average more passes (%d of 19)", n);
        assert_non_null(strstr(lpv_engine_last_plan(lpvt_engine)->pass[LPV_PASS_PROBES].reason, want));
        assert_int_equal((int)lpv_stats_get(lpv_engine_last_stats(lpvt_engine), "probes_updated")->v[0], brought);
    }
    assert_int_equal(lpv_engine_tick(lpvt_engine, err, sizeof err), 0); /* then the round robin or nothing */
    assert_null(strstr(lpv_engine_last_plan(lpvt_engine)->pass[LPV_PASS_PROBES].reason, "average more passes"));

    /* the same place afresh: every probe, 4 passes */
    lpv_engine_forget(lpvt_engine);
    assert_int_equal(lpv_engine_tick(lpvt_engine, err, sizeof err), 0);
    assert_int_equal((int)lpv_stats_get(lpv_engine_last_stats(lpvt_engine), "probes_updated")->v[0], 4 * PROBES);
    assert_int_equal(lpv_engine_read_grid(lpvt_engine, LPV_GRID_ACCUMULATED, fresh, PROBES), PROBES);
    double sum_scrolled = 0.0, sum_fresh = 0.0;
    for (int z = 0; z < N; ++z)
        for (int y = 0; y < N; ++y)
            for (int x = N - 2; x < N; ++x) {
                const int p = x + N * (y + N * z);
                sum_scrolled += after[p].r[0] + after[p].g[0] + after[p].b[0];
                sum_fresh += fresh[p].r[0] + fresh[p].g[0] + fresh[p].b[0];
            }
    const double fresh_ms = probes_ms(lpv_engine_last_stats(lpvt_engine));
    printf("the probes a scroll brought in: %.3f of a fresh warmup's light there; %d of %d probes traced, the probes' "
           "passes %.1f ms against a fresh warmup's %.1f ms (%.3f)\n",
           sum_scrolled / sum_fresh, brought, PROBES, scroll_ms, fresh_ms, scroll_ms / fresh_ms);
    /* the same passes, their neighbours' light from more bounces: not
     * darker, and not more than the bounces past the warmup's add */
    assert_true(sum_scrolled >= 0.9 * sum_fresh && sum_scrolled <= 1.5 * sum_fresh);
    lpv_scene_free(&room);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_glowing_box_gives_pi_l),
        cmocka_unit_test(test_update_matches_cpu_oracle),
        cmocka_unit_test(test_probes_in_a_block_are_off),
        cmocka_unit_test(test_probes_relocate),
        cmocka_unit_test(test_probes_relocate_after_geometry_moves),
        cmocka_unit_test(test_lookup_matches_cpu_oracle),
        cmocka_unit_test(test_probes_follow_a_moved_light),
        cmocka_unit_test(test_probes_scroll_with_the_camera),
        cmocka_unit_test(test_probes_follow_moved_geometry),
        cmocka_unit_test(test_forget_gives_a_fresh_tick),
    };
    return cmocka_run_group_tests(tests, lpvt_gl_setup, lpvt_gl_teardown);
}
