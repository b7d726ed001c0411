/*
 * test_reach.c - the scene's air spaces and which a light reaches
 * (core/reach.c), pure C: a lamp in a closed box, two rooms sharing a wall,
 * a doorway, a directional light outside, an emissive panel, a light
 * inside a thin slab.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "iv_points.h"
#include "reach.h"
#include "settings.h"
#include "scene_build.h"

static void add_box(lpv_scene *s, int m, float x0, float y0, float z0, float x1, float y1, float z1)
{
    assert_true(lpv_scene_add_box(s, m, (float[3]){x0, y0, z0}, (float[3]){x1, y1, z1}) >= 0);
}

/* A 4 x 3 x 4 m room of 10 cm walls; inside it a 0.6 m box of 2 cm walls
 * (closed, or without its lid), a point light inside the box. */
static void lamp_scene(lpv_scene *s, int closed)
{
    memset(s, 0, sizeof *s);
    int grey = lpv_scene_add_material(s, "grey", (float[3]){0.6f, 0.6f, 0.6f}, NULL);
    assert_true(grey >= 0);
    add_box(s, grey, -2.1f, -0.1f, -2.1f, 2.1f, 0.0f, 2.1f); /* floor */
    add_box(s, grey, -2.1f, 3.0f, -2.1f, 2.1f, 3.1f, 2.1f);  /* ceiling */
    add_box(s, grey, -2.1f, 0.0f, -2.1f, -2.0f, 3.0f, 2.1f);
    add_box(s, grey, 2.0f, 0.0f, -2.1f, 2.1f, 3.0f, 2.1f);
    add_box(s, grey, -2.0f, 0.0f, -2.1f, 2.0f, 3.0f, -2.0f);
    add_box(s, grey, -2.0f, 0.0f, 2.0f, 2.0f, 3.0f, 2.1f);
    const float lo[3] = {-0.3f, 0.5f, -0.3f}, hi[3] = {0.3f, 1.1f, 0.3f}, t = 0.02f;
    add_box(s, grey, lo[0], lo[1], lo[2], hi[0], lo[1] + t, hi[2]);
    if (closed)
        add_box(s, grey, lo[0], hi[1] - t, lo[2], hi[0], hi[1], hi[2]);
    add_box(s, grey, lo[0], lo[1], lo[2], lo[0] + t, hi[1], hi[2]);
    add_box(s, grey, hi[0] - t, lo[1], lo[2], hi[0], hi[1], hi[2]);
    add_box(s, grey, lo[0], lo[1], lo[2], hi[0], hi[1], lo[2] + t);
    add_box(s, grey, lo[0], lo[1], hi[2] - t, hi[0], hi[1], hi[2]);
    assert_non_null(lpv_scene_add_point_light(s, (float[3]){0.0f, 0.8f, 0.0f}, 5.0f));
    lpv_scene_compute_bounds(s);
}

static void build_and_light(lpv_reach *r, const lpv_scene *s)
{
    char err[256];
    assert_int_equal(lpv_reach_build(r, s, 0, err, sizeof err), 0);
    lpv_reach_light(r, s, s->lights, s->light_count);
    assert_int_equal(r->unsure, 0);
}

static const float UP[3] = {0, 1, 0}, DOWN[3] = {0, -1, 0}, PX[3] = {1, 0, 0}, NX[3] = {-1, 0, 0};

static void test_closed_box_keeps_its_light(void **state)
{
    (void)state;
    lpv_scene s;
    lamp_scene(&s, 1);
    lpv_reach r;
    build_and_light(&r, &s);
    /* inside the box: the floor of the box, facing up, and the inner walls */
    assert_true(lpv_reach_at(&r, (float[3]){0.0f, 0.52f, 0.0f}, UP) == 1.0f);
    assert_true(lpv_reach_at(&r, (float[3]){0.28f, 0.8f, 0.0f}, NX) == 1.0f);
    /* outside: the room's floor, walls, ceiling and the box's outer faces */
    assert_true(lpv_reach_at(&r, (float[3]){1.0f, 0.0f, 1.0f}, UP) == 0.0f);
    assert_true(lpv_reach_at(&r, (float[3]){-2.0f, 1.5f, 0.0f}, PX) == 0.0f);
    assert_true(lpv_reach_at(&r, (float[3]){0.0f, 3.0f, 0.0f}, DOWN) == 0.0f);
    assert_true(lpv_reach_at(&r, (float[3]){0.3f, 0.8f, 0.0f}, PX) == 0.0f);
    assert_true(lpv_reach_at(&r, (float[3]){0.0f, 1.1f, 0.0f}, UP) == 0.0f);
    assert_true(r.components >= 3); /* outside, room, box (and the walls' insides) */
    assert_int_equal(r.lit_components, 1);
    assert_true(r.voxel < 0.05f); /* finer than the room's walls are thick */
    /* the lamp moves within its box: the same spaces are lit, nothing to send
     * again; out of the box into the room: the room is lit */
    s.lights[0].position[0] = 0.1f;
    assert_int_equal(lpv_reach_light(&r, &s, s.lights, s.light_count), 0);
    assert_true(lpv_reach_at(&r, (float[3]){1.0f, 0.0f, 1.0f}, UP) == 0.0f);
    s.lights[0].position[1] = 2.0f;
    assert_int_equal(lpv_reach_light(&r, &s, s.lights, s.light_count), 1);
    assert_true(lpv_reach_at(&r, (float[3]){1.0f, 0.0f, 1.0f}, UP) == 1.0f);
    assert_true(lpv_reach_at(&r, (float[3]){0.0f, 0.52f, 0.0f}, UP) == 0.0f);
    lpv_reach_free(&r);
    lpv_scene_free(&s);
}

static void test_open_box_lights_the_room(void **state)
{
    (void)state;
    lpv_scene s;
    lamp_scene(&s, 0);
    lpv_reach r;
    build_and_light(&r, &s);
    assert_true(lpv_reach_at(&r, (float[3]){1.0f, 0.0f, 1.0f}, UP) == 1.0f);
    assert_true(lpv_reach_at(&r, (float[3]){0.3f, 0.8f, 0.0f}, PX) == 1.0f);
    assert_true(lpv_reach_at(&r, (float[3]){0.0f, 3.0f, 0.0f}, DOWN) == 1.0f);
    /* the outside of the room stays dark: a point light lights only its own space */
    assert_true(lpv_reach_at(&r, (float[3]){0.0f, 3.1f, 0.0f}, UP) == 0.0f);
    lpv_reach_free(&r);
    lpv_scene_free(&s);
}

/* A directional light lights the air outside the scene and what opens onto
 * it; an emitter lights both sides of itself. */
static void test_directional_and_emitters(void **state)
{
    (void)state;
    lpv_scene s = {0};
    int grey = lpv_scene_add_material(&s, "grey", (float[3]){0.6f, 0.6f, 0.6f}, NULL);
    int lamp = lpv_scene_add_material(&s, "lamp", (float[3]){0.8f, 0.8f, 0.8f}, (float[3]){5.0f, 5.0f, 5.0f});
    add_box(&s, grey, -5.0f, -0.1f, -5.0f, 5.0f, 0.0f, 5.0f);       /* ground */
    add_box(&s, grey, 1.0f, 0.0f, 1.0f, 3.0f, 2.0f, 3.0f);          /* a closed block (solid inside) */
    /* a closed 1 m shell (four walls, floor, lid) holding an emissive quad facing up */
    add_box(&s, grey, -3.0f, 0.0f, -3.0f, -2.0f, 0.05f, -2.0f);
    add_box(&s, grey, -3.0f, 0.95f, -3.0f, -2.0f, 1.0f, -2.0f);
    add_box(&s, grey, -3.0f, 0.0f, -3.0f, -2.95f, 1.0f, -2.0f);
    add_box(&s, grey, -2.05f, 0.0f, -3.0f, -2.0f, 1.0f, -2.0f);
    add_box(&s, grey, -3.0f, 0.0f, -3.0f, -2.0f, 1.0f, -2.95f);
    add_box(&s, grey, -3.0f, 0.0f, -2.05f, -2.0f, 1.0f, -2.0f);
    const float q[4][3] = {{-2.7f, 0.5f, -2.3f}, {-2.3f, 0.5f, -2.3f}, {-2.3f, 0.5f, -2.7f}, {-2.7f, 0.5f, -2.7f}};
    assert_true(lpv_scene_add_quad(&s, lamp, q, NULL) >= 0);
    lpv_scene_compute_bounds(&s);
    lpv_reach r;
    char err[256];
    assert_int_equal(lpv_reach_build(&r, &s, 0, err, sizeof err), 0);
    /* no lights at all: only the emitter's shell is lit */
    lpv_reach_light(&r, &s, NULL, 0);
    assert_int_equal(r.unsure, 0);
    assert_true(lpv_reach_at(&r, (float[3]){0.0f, 0.0f, 0.0f}, UP) == 0.0f);
    assert_true(lpv_reach_at(&r, (float[3]){-2.5f, 0.05f, -2.5f}, UP) == 1.0f); /* under the panel */
    assert_true(lpv_reach_at(&r, (float[3]){-2.5f, 0.95f, -2.5f}, DOWN) == 1.0f); /* above its back */
    /* a sun: the ground and the block's faces are lit, the shell's inside still is */
    lpv_light sun = {.type = LPV_LIGHT_DIRECTIONAL, .color = {1, 1, 1}, .intensity = 1.0f, .direction = {0, -1, 0}};
    lpv_reach_light(&r, &s, &sun, 1);
    assert_true(lpv_reach_at(&r, (float[3]){0.0f, 0.0f, 0.0f}, UP) == 1.0f);
    assert_true(lpv_reach_at(&r, (float[3]){3.0f, 1.0f, 2.0f}, PX) == 1.0f);
    assert_true(lpv_reach_at(&r, (float[3]){-2.5f, 0.05f, -2.5f}, UP) == 1.0f);
    lpv_reach_free(&r);
    lpv_scene_free(&s);
}

/* Two rooms sharing a 10 cm wall: a lamp in one leaves the other dark; a
 * 0.8 m doorway in the wall joins them. */
static void test_two_rooms(void **state)
{
    (void)state;
    for (int door = 0; door <= 1; ++door) {
        lpv_scene s = {0};
        int grey = lpv_scene_add_material(&s, "grey", (float[3]){0.6f, 0.6f, 0.6f}, NULL);
        add_box(&s, grey, -4.1f, -0.1f, -2.1f, 4.1f, 0.0f, 2.1f);
        add_box(&s, grey, -4.1f, 3.0f, -2.1f, 4.1f, 3.1f, 2.1f);
        add_box(&s, grey, -4.1f, 0.0f, -2.1f, 4.1f, 3.0f, -2.0f);
        add_box(&s, grey, -4.1f, 0.0f, 2.0f, 4.1f, 3.0f, 2.1f);
        add_box(&s, grey, -4.1f, 0.0f, -2.0f, -4.0f, 3.0f, 2.0f);
        add_box(&s, grey, 4.0f, 0.0f, -2.0f, 4.1f, 3.0f, 2.0f);
        if (door) {
            add_box(&s, grey, -0.05f, 0.0f, -2.0f, 0.05f, 3.0f, -0.4f);
            add_box(&s, grey, -0.05f, 0.0f, 0.4f, 0.05f, 3.0f, 2.0f);
            add_box(&s, grey, -0.05f, 2.1f, -0.4f, 0.05f, 3.0f, 0.4f);
        } else
            add_box(&s, grey, -0.05f, 0.0f, -2.0f, 0.05f, 3.0f, 2.0f);
        assert_non_null(lpv_scene_add_point_light(&s, (float[3]){-2.0f, 2.2f, 0.0f}, 5.0f));
        lpv_scene_compute_bounds(&s);
        lpv_reach r;
        build_and_light(&r, &s);
        assert_true(lpv_reach_at(&r, (float[3]){-2.0f, 0.0f, 0.0f}, UP) == 1.0f);
        assert_true(lpv_reach_at(&r, (float[3]){-0.05f, 1.5f, 1.0f}, NX) == 1.0f);
        const float expect = door ? 1.0f : 0.0f;
        assert_true(lpv_reach_at(&r, (float[3]){2.0f, 0.0f, 0.0f}, UP) == expect);
        assert_true(lpv_reach_at(&r, (float[3]){0.05f, 1.5f, 1.0f}, PX) == expect);
        lpv_reach_free(&r);
        lpv_scene_free(&s);
    }
}

/* A light inside a solid voxel (here in a floor slab thinner than a voxel)
 * lights the air around that voxel: both sides of the slab. */
static void test_light_in_thin_slab(void **state)
{
    (void)state;
    lpv_scene s = {0};
    int grey = lpv_scene_add_material(&s, "grey", (float[3]){0.6f, 0.6f, 0.6f}, NULL);
    add_box(&s, grey, -2.0f, -0.005f, -2.0f, 2.0f, 0.0f, 2.0f);
    add_box(&s, grey, -2.0f, -1.0f, -2.0f, 2.0f, 2.0f, -1.9f); /* a wall, so the bounds have depth */
    assert_non_null(lpv_scene_add_point_light(&s, (float[3]){0.0f, -0.0025f, 0.0f}, 5.0f));
    lpv_scene_compute_bounds(&s);
    lpv_reach r;
    build_and_light(&r, &s);
    assert_true(r.voxel > 0.005f);
    assert_true(lpv_reach_at(&r, (float[3]){1.0f, 0.0f, 1.0f}, UP) == 1.0f);
    assert_true(lpv_reach_at(&r, (float[3]){1.0f, -0.005f, 1.0f}, DOWN) == 1.0f);
    lpv_reach_free(&r);
    lpv_scene_free(&s);
}

/* A lamp closer under a ceiling than the voxels are wide: its voxel is
 * solid, and the air on both sides of the ceiling lies around it. Above the
 * ceiling is the hollow inside of a 3 m block (a hill, the next storey): the
 * lamp lights the room under it and not that. Looked at closer
 * (LPV_REACH_CLOSER), the lamp's air is the room's; every air voxel around
 * it lit the block's inside too, with 0.5 m voxels, at every height in the
 * solid voxel. */
static void test_lamp_under_a_thick_ceiling(void **state)
{
    (void)state;
    lpv_scene s = {0};
    int grey = lpv_scene_add_material(&s, "grey", (float[3]){0.6f, 0.6f, 0.6f}, NULL);
    add_box(&s, grey, -10.0f, -0.2f, -10.0f, 10.0f, 0.0f, 10.0f); /* floor */
    add_box(&s, grey, -10.0f, 2.6f, -10.0f, 10.0f, 5.6f, 10.0f);  /* the block over the room, hollow */
    lpv_light *lamp = lpv_scene_add_point_light(&s, (float[3]){0.0f, 2.4f, 0.0f}, 5.0f);
    assert_non_null(lamp);
    lpv_scene_compute_bounds(&s);
    char err[256];
    lpv_reach r;
    assert_int_equal(lpv_reach_build(&r, &s, 20000, err, sizeof err), 0);
    assert_true(r.voxel > 0.3f);
    int tried = 0;
    for (float below = 0.05f; below < 1.0f; below += 0.1f) {
        lamp->position[1] = 2.6f - below * r.voxel;
        int c[3];
        for (int k = 0; k < 3; ++k)
            c[k] = (int)floorf((lamp->position[k] - r.origin[k]) / r.voxel);
        if (r.label[(size_t)c[0] + (size_t)r.dims[0] * ((size_t)c[1] + (size_t)r.dims[1] * (size_t)c[2])] != 0)
            continue; /* the lamp's voxel is air: nothing to look at closer */
        lpv_reach_light(&r, &s, s.lights, s.light_count);
        assert_int_equal(r.unsure, 0);
        assert_int_equal(lpv_reach_lit_at(&r, (float[3]){0.0f, 1.2f, 3.0f}), 1);  /* the room */
        assert_int_equal(lpv_reach_lit_at(&r, (float[3]){0.0f, 4.1f, 0.0f}), 0);  /* inside the block */
        assert_int_equal(lpv_reach_lit_at(&r, (float[3]){3.0f, 4.1f, -3.0f}), 0);
        assert_int_equal(r.lit_components, 1);
        /* without the scene, every air voxel around the lamp: the block's inside too */
        lpv_reach_light(&r, NULL, s.lights, s.light_count);
        assert_int_equal(lpv_reach_lit_at(&r, (float[3]){0.0f, 4.1f, 0.0f}), 1);
        tried++;
    }
    print_message("voxel %.3f m: %d lamp heights in a solid voxel\n", (double)r.voxel, tried);
    assert_true(tried >= 2);
    lpv_reach_free(&r);
    lpv_scene_free(&s);
}

/* A closed box of zero-thickness walls facing in, x in [-w/2, w/2], y in
 * [0, h], z in [-len/2, len/2], and with slab a 240 m x 240 m block of
 * ground 10 m thick on it (wide bounds, narrow air). */
static void closed_box(lpv_scene *s, float w, float h, float len, int slab)
{
    memset(s, 0, sizeof *s);
    int grey = lpv_scene_add_material(s, "grey", (float[3]){0.6f, 0.6f, 0.6f}, NULL);
    const float x0 = -w / 2, x1 = w / 2, y0 = 0.0f, y1 = h, z0 = -len / 2, z1 = len / 2;
    const float q[6][4][3] = {
        {{x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1}}, {{x0, y1, z0}, {x0, y1, z1}, {x1, y1, z1}, {x1, y1, z0}},
        {{x0, y0, z0}, {x0, y0, z1}, {x0, y1, z1}, {x0, y1, z0}}, {{x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, y0, z1}},
        {{x0, y0, z0}, {x0, y1, z0}, {x1, y1, z0}, {x1, y0, z0}}, {{x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1}}};
    for (int i = 0; i < 6; ++i)
        assert_true(lpv_scene_add_quad(s, grey, q[i], NULL) >= 0);
    if (slab)
        add_box(s, grey, -120.0f, h + 0.2f, -120.0f, 120.0f, h + 10.2f, 120.0f);
    lpv_scene_compute_bounds(s);
}

/* The free path 4 V / S of a closed box, and iv's voxels from it: a long
 * closed tunnel gets voxels a fraction of its width (at the same voxel
 * budget as a cube at the setting), a room keeps the setting. */
static void test_free_path_sizes_iv(void **state)
{
    (void)state;
    for (int tunnel = 0; tunnel <= 1; ++tunnel) {
        const float len = tunnel ? 240.0f : 4.0f, w = tunnel ? 3.0f : 4.0f, h = tunnel ? 2.6f : 3.0f;
        lpv_scene s;
        closed_box(&s, w, h, len, 0);
        lpv_reach r;
        char err[256];
        assert_int_equal(lpv_reach_build(&r, &s, 0, err, sizeof err), 0);
        const double area = 2.0 * ((double)w * h + (double)w * len + (double)h * len);
        const double want = 4.0 * (double)w * h * len / area;
        printf("%s: free path %.3f m (4 V / S = %.3f m), voxels %.3f m\n", tunnel ? "tunnel" : "room",
               (double)r.free_path, want, (double)r.voxel);
        /* the voxels inside the walls' conservative voxels are not air */
        assert_true(fabs(r.free_path - want) < 0.1 * want);
        lpv_settings set = {.technique = LPV_TECHNIQUE_ID_IV};
        lpv_settings_resolve(&set);
        lpv_grid g, plain;
        assert_int_equal(lpv_iv_place(&set, s.bounds_min, s.bounds_max, r.free_path, &g), 0);
        assert_int_equal(lpv_iv_place(&set, s.bounds_min, s.bounds_max, 0.0f, &plain), 0);
        const double budget = pow(set.iv.resolution + 1.0, 3.0);
        printf("  iv voxels %.3f m (%d x %d x %d), without the free path %.3f m\n", (double)g.cell_size, g.dims[0],
               g.dims[1], g.dims[2], (double)plain.cell_size);
        assert_true((double)lpv_grid_cell_count(&g) <= budget);
        if (tunnel)
            assert_true(g.cell_size < w / 3.0f && plain.cell_size > w);
        else
            assert_memory_equal(&g, &plain, sizeof g);
        lpv_reach_free(&r);
        lpv_scene_free(&s);
    }
}

static float chord_at(const lpv_scene *s, const float p[3])
{
    lpv_reach r;
    char err[256];
    assert_int_equal(lpv_reach_build(&r, s, 0, err, sizeof err), 0);
    const float c = lpv_reach_view_chord(&r, p);
    lpv_reach_free(&r);
    return c;
}

/* How wide the space around a point is, whatever the bounds: the median
 * chord in a 3 m x 2.6 m tunnel is about the same 60 m or 240 m long and
 * under a 240 m wide block of ground, a few metres where the bounds' sides
 * (240 m) say nothing of it; in a room it is about the same from the middle
 * and a quarter of the way from the walls (nearer a corner the oblique
 * chords are cut short); open ground gives INFINITY, a point outside the
 * voxels 0. */
static void test_view_chord(void **state)
{
    (void)state;
    lpv_scene s;
    const float mid[3] = {0.0f, 1.3f, 0.0f};
    float tunnel[3];
    for (int k = 0; k < 3; ++k) {
        closed_box(&s, 3.0f, 2.6f, k == 0 ? 60.0f : 240.0f, k == 2);
        tunnel[k] = chord_at(&s, mid);
        lpv_scene_free(&s);
    }
    printf("tunnel chords: 60 m %.3f, 240 m %.3f, under ground %.3f\n", (double)tunnel[0], (double)tunnel[1],
           (double)tunnel[2]);
    /* under the ground the bounds hold 12 times the volume in the same voxel
     * budget: voxels of 0.7 m instead of 0.23 m, and a wall's conservative
     * voxels take up to one off each side of the air */
    for (int k = 0; k < 3; ++k) {
        assert_true(tunnel[k] > 2.4f && tunnel[k] < 6.0f);
        assert_true(fabsf(tunnel[k] - tunnel[1]) < (k == 2 ? 0.25f : 0.1f) * tunnel[1]);
    }
    closed_box(&s, 4.0f, 3.0f, 4.0f, 0);
    const float centre = chord_at(&s, (float[3]){0.0f, 1.5f, 0.0f}),
                aside = chord_at(&s, (float[3]){1.0f, 1.0f, 1.0f});
    printf("room chords: centre %.3f, a quarter of the way from the walls %.3f\n", (double)centre, (double)aside);
    assert_true(centre > 3.0f && centre < 6.0f);
    assert_true(fabsf(aside - centre) < 0.25f * centre);
    lpv_scene_free(&s);
    memset(&s, 0, sizeof s);
    int grey = lpv_scene_add_material(&s, "grey", (float[3]){0.6f, 0.6f, 0.6f}, NULL);
    add_box(&s, grey, -50.0f, -0.1f, -50.0f, 50.0f, 0.0f, 50.0f);
    add_box(&s, grey, 40.0f, 0.0f, 40.0f, 40.2f, 5.0f, 40.2f); /* a post: bounds 5 m high */
    lpv_scene_compute_bounds(&s);
    assert_true(isinf(chord_at(&s, (float[3]){0.0f, 1.0f, 0.0f})));
    assert_true(chord_at(&s, (float[3]){0.0f, 500.0f, 0.0f}) == 0.0f);
    lpv_scene_free(&s);
}

/* Where light can go: a lamp in the tunnel under the hill lights only the
 * tunnel's air, so the lit box is the tunnel (grown by a voxel), 240 m long
 * but a few metres across where the bounds are 240 m wide, and its free
 * path is the tunnel's (4 V / S = 2.8 m for 3 m x 2.6 m), not the open
 * air's under the hill; a light outside the tunnel lights the rest. */
static void test_lit_box(void **state)
{
    (void)state;
    lpv_scene s;
    closed_box(&s, 3.0f, 2.6f, 240.0f, 1);
    assert_non_null(lpv_scene_add_point_light(&s, (float[3]){0.0f, 1.3f, 20.0f}, 5.0f));
    lpv_reach r;
    build_and_light(&r, &s);
    printf("lit box [%.2f %.2f %.2f] .. [%.2f %.2f %.2f], voxel %.3f m, lit free path %.3f m, scene's %.3f m\n",
           (double)r.lit_min[0], (double)r.lit_min[1], (double)r.lit_min[2], (double)r.lit_max[0],
           (double)r.lit_max[1], (double)r.lit_max[2], (double)r.voxel, (double)r.lit_free_path, (double)r.free_path);
    assert_int_equal(r.lit_box, 1);
    assert_true(r.lit_min[0] > -1.5f - 2.0f * r.voxel && r.lit_max[0] < 1.5f + 2.0f * r.voxel);
    assert_true(r.lit_min[1] > -2.0f * r.voxel && r.lit_max[1] < 2.6f + 2.0f * r.voxel);
    assert_true(r.lit_max[2] - r.lit_min[2] > 235.0f);
    /* the walls' conservative voxels (0.78 m here) take air off each side */
    const float tunnel = 4.0f * 3.0f * 2.6f / (2.0f * (3.0f + 2.6f));
    assert_true(r.lit_free_path > 0.6f * tunnel && r.lit_free_path < 1.1f * tunnel);
    assert_true(r.free_path > 3.0f * tunnel); /* the scene's: the open air under the hill */
    lpv_reach_free(&r);
    lpv_scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_closed_box_keeps_its_light),
        cmocka_unit_test(test_open_box_lights_the_room),
        cmocka_unit_test(test_directional_and_emitters),
        cmocka_unit_test(test_two_rooms),
        cmocka_unit_test(test_light_in_thin_slab),
        cmocka_unit_test(test_lamp_under_a_thick_ceiling),
        cmocka_unit_test(test_free_path_sizes_iv),
        cmocka_unit_test(test_view_chord),
        cmocka_unit_test(test_lit_box),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
