/*
 * hard_cases.c - see hard_cases.h. Every case is a closed 1 m grey room
 * (so the reference has no light escaping to infinity and every pixel hits
 * something) with a camera inside it near the front wall, plus what makes
 * the case hard.
 */
#include "hard_cases.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "grid.h"
#include "scene_build.h"

/* A quad whose front faces `inward`: the corners form a loop and are
 * reversed when their winding points the other way, so callers list faces
 * in any order. normal: stored as given (NULL = the winding's). */
static int add_face(lpv_scene *s, int m, const float c[4][3], const float inward[3], const float *normal)
{
    float a[3], b[3];
    for (int k = 0; k < 3; ++k) {
        a[k] = c[2][k] - c[0][k];
        b[k] = c[3][k] - c[1][k];
    }
    float n[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    if (n[0] * inward[0] + n[1] * inward[1] + n[2] * inward[2] >= 0.0f)
        return lpv_scene_add_quad(s, m, c, normal);
    const float r[4][3] = {{c[3][0], c[3][1], c[3][2]},
                           {c[2][0], c[2][1], c[2][2]},
                           {c[1][0], c[1][1], c[1][2]},
                           {c[0][0], c[0][1], c[0][2]}};
    return lpv_scene_add_quad(s, m, r, normal);
}

/* The closed unit room [0,1]^3, faces towards the inside, albedo 0.7. The
 * floor's vertex normal is floor_normal (NULL: +Y), so the degenerate case
 * can store a NaN one. Returns the material index, or -1. */
static int make_room(lpv_scene *s, const float *floor_normal)
{
    int m = lpv_scene_add_material(s, "grey", (const float[3]){0.7f, 0.7f, 0.7f}, NULL);
    if (m < 0)
        return -1;
    static const struct {
        float c[4][3];
        float in[3];
    } faces[6] = {
        {{{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}}, {0, 1, 0}},  /* floor (first: vertices 0-3) */
        {{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {0, 0, 1}},  /* back (vertices 4-7) */
        {{{0, 1, 0}, {1, 1, 0}, {1, 1, 1}, {0, 1, 1}}, {0, -1, 0}}, /* ceiling */
        {{{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}, {0, 0, -1}}, /* front */
        {{{0, 0, 0}, {0, 1, 0}, {0, 1, 1}, {0, 0, 1}}, {1, 0, 0}},  /* left */
        {{{1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {1, 0, 1}}, {-1, 0, 0}}, /* right */
    };
    for (int f = 0; f < 6; ++f)
        if (add_face(s, m, faces[f].c, faces[f].in, f == 0 ? floor_normal : NULL) < 0)
            return -1;
    return m;
}

/* The usual camera: inside, near the front wall, looking at the back wall
 * and a little down, wide enough to see floor, ceiling and side walls. */
static void default_camera(lpv_hard_scene *h)
{
    const float eye[3] = {0.5f, 0.5f, 0.92f}, target[3] = {0.5f, 0.42f, 0.0f};
    memcpy(h->eye, eye, sizeof eye);
    memcpy(h->target, target, sizeof target);
    h->yfov = 1.4f;
}

static int point_light(lpv_scene *s, float x, float y, float z, float intensity)
{
    return lpv_scene_add_point_light(s, (const float[3]){x, y, z}, intensity) ? 0 : -1;
}

/* Room plus one light at the centre; the grid as given. */
static int centred(lpv_hard_scene *h, float intensity, int gx, int gy, int gz, int iterations)
{
    h->settings = (lpv_settings){.technique = LPV_TECHNIQUE_ID_LPV, .grid_dims = {gx, gy, gz}, .rsm_size = 32, .lpv.iterations = iterations};
    return make_room(&h->scene, NULL) < 0 ? -1 : point_light(&h->scene, 0.5f, 0.5f, 0.5f, intensity);
}

static int build_dynamic_range(lpv_hard_scene *h)
{
    h->settings = (lpv_settings){.technique = LPV_TECHNIQUE_ID_LPV, .grid_dims = {16, 16, 16}, .rsm_size = 64};
    if (make_room(&h->scene, NULL) < 0)
        return -1;
    return point_light(&h->scene, 0.2f, 0.5f, 0.5f, 1e3f) | point_light(&h->scene, 0.8f, 0.5f, 0.5f, 1e-3f);
}

static int build_light_on_corner(lpv_hard_scene *h)
{
    h->settings = (lpv_settings){.technique = LPV_TECHNIQUE_ID_LPV, .grid_dims = {8, 8, 8}, .rsm_size = 32, .bounds_min = {0, 0, 0}, .bounds_max = {1, 1, 1}};
    lpv_grid g;
    if (make_room(&h->scene, NULL) < 0 ||
        lpv_grid_place(h->settings.grid_dims, h->settings.bounds_min, h->settings.bounds_max, &g) != 0)
        return -1;
    /* exactly on the corner shared by cells (3..4, 4..5, 3..4): the corner
     * is representable, so no rounding moves it into one cell */
    return point_light(&h->scene, g.origin[0] + 4 * g.cell_size, g.origin[1] + 5 * g.cell_size,
                       g.origin[2] + 4 * g.cell_size, 2.0f);
}

static int build_vpls_on_boundary(lpv_hard_scene *h)
{
    h->settings = (lpv_settings){.technique = LPV_TECHNIQUE_ID_LPV, .grid_dims = {8, 8, 8}, .rsm_size = 32, .bounds_min = {0, 0, 0}, .bounds_max = {1, 1, 1}};
    lpv_grid g;
    if (make_room(&h->scene, NULL) < 0 ||
        lpv_grid_place(h->settings.grid_dims, h->settings.bounds_min, h->settings.bounds_max, &g) != 0)
        return -1;
    /* VPLs are injected half a cell in front of their surface: shifting the
     * bounds down by half a cell puts the floor's VPLs exactly on the grid's
     * lower face (and the ceiling's outside the grid) */
    h->settings.bounds_min[1] = -0.5f * g.cell_size;
    h->settings.bounds_max[1] = 1.0f - 0.5f * g.cell_size;
    return point_light(&h->scene, 0.5f, 0.9f, 0.5f, 1.0f);
}

/* The room split at x = 0.5 by a 1 mm wall, open only in a doorway at the
 * front (z 0.8..1, y below 0.75). The camera stands in the doorway, so the
 * wall is seen edge-on: lit side on the left, dark side on the right. In the
 * reference the dark side gets only what comes through the doorway; an LPV
 * cell (6.7 cm with 16^3 cells) is 67 times thicker than the wall, so any
 * leak through it shows there. */
static int build_thin_wall(lpv_hard_scene *h)
{
    h->settings = (lpv_settings){.technique = LPV_TECHNIQUE_ID_LPV, .grid_dims = {16, 16, 16}, .rsm_size = 64};
    int m = make_room(&h->scene, NULL);
    if (m < 0)
        return -1;
    const float x0 = 0.4995f, x1 = 0.5005f;
    if (lpv_scene_add_box(&h->scene, m, (const float[3]){x0, 0, 0}, (const float[3]){x1, 1, 0.8f}) < 0 ||
        lpv_scene_add_box(&h->scene, m, (const float[3]){x0, 0.75f, 0.8f}, (const float[3]){x1, 1, 1}) < 0)
        return -1;
    const float eye[3] = {0.5f, 0.4f, 0.97f}, target[3] = {0.5f, 0.35f, 0.0f};
    memcpy(h->eye, eye, sizeof eye);
    memcpy(h->target, target, sizeof target);
    h->yfov = 1.4f;
    /* between the wall's centre and its dark face, up to the right wall */
    h->has_dark_side = 1;
    const float lo[3] = {0.5002f, -0.01f, -0.01f}, hi[3] = {1.01f, 1.01f, 1.01f};
    memcpy(h->dark_lo, lo, sizeof lo);
    memcpy(h->dark_hi, hi, sizeof hi);
    return point_light(&h->scene, 0.25f, 0.7f, 0.35f, 1.0f);
}

static int build_degenerate(lpv_hard_scene *h)
{
    h->settings = (lpv_settings){.technique = LPV_TECHNIQUE_ID_LPV, .grid_dims = {8, 8, 8}, .rsm_size = 32};
    lpv_scene *s = &h->scene;
    int m = make_room(s, (const float[3]){NAN, NAN, NAN});
    if (m < 0)
        return -1;
    /* a zero-length normal on the back wall's first vertex */
    memset(s->vertices[4].normal, 0, sizeof s->vertices[4].normal);
    /* a "quad" of four collinear corners: two zero-area triangles */
    const float line[4][3] = {{0.2f, 0.3f, 0.2f}, {0.4f, 0.3f, 0.2f}, {0.6f, 0.3f, 0.2f}, {0.8f, 0.3f, 0.2f}};
    if (lpv_scene_add_quad(s, m, line, NULL) < 0)
        return -1;
    /* and a triangle repeating an index, appended to that last draw */
    uint32_t *idx = realloc(s->indices, (s->index_count + 3) * sizeof *idx);
    if (!idx)
        return -1;
    s->indices = idx;
    idx[s->index_count++] = 0;
    idx[s->index_count++] = 0;
    idx[s->index_count++] = 1;
    s->draws[s->draw_count - 1].index_count += 3;
    return point_light(s, 0.5f, 0.8f, 0.5f, 1.0f);
}

static int build_extreme(lpv_hard_scene *h)
{
    return centred(h, 1e30f, 8, 8, 8, 0);
}

static int build_steps_1000(lpv_hard_scene *h)
{
    return centred(h, 1.0f, 8, 8, 8, 1000);
}

static int build_one_cell(lpv_hard_scene *h)
{
    return centred(h, 1.0f, 1, 1, 1, 0);
}

static int build_flat(lpv_hard_scene *h)
{
    return centred(h, 1.0f, 1, 1, 64, 0);
}

static const struct {
    lpv_hard_case_info info;
    int (*build)(lpv_hard_scene *h);
} CASES[] = {
    {{"dynamic_range_1e6", "two lights of 1e3 and 1e-3 W/sr (1e6 apart) in one room"}, build_dynamic_range},
    {{"extreme_intensity_1e30", "one point light of 1e30 W/sr: float range, no overflow to Inf"}, build_extreme},
    {{"light_on_cell_corner", "a point light exactly on a corner shared by 8 cells"}, build_light_on_corner},
    {{"vpls_on_grid_boundary", "grid bounds ending exactly on the floor: VPLs on the grid's faces"},
     build_vpls_on_boundary},
    {{"thin_wall", "a 1 mm wall (1/67 of a cell) splits the room, light on one side, doorway at the front"},
     build_thin_wall},
    {{"steps_1000", "1000 propagation iterations: no growth, no drift to NaN"}, build_steps_1000},
    {{"degenerate_geometry", "NaN and zero vertex normals, zero-area triangles"}, build_degenerate},
    {{"one_cell_grid", "a 1x1x1 grid: every neighbour is outside"}, build_one_cell},
    {{"flat_grid_1x1x64", "a 1x1x64 grid: propagation along one axis only"}, build_flat},
};
#define NCASES (sizeof CASES / sizeof CASES[0])

size_t lpv_hard_case_count(void)
{
    return NCASES;
}

const lpv_hard_case_info *lpv_hard_case_get(size_t i)
{
    return i < NCASES ? &CASES[i].info : NULL;
}

int lpv_hard_case_find(const char *name)
{
    for (size_t i = 0; name && i < NCASES; ++i)
        if (strcmp(CASES[i].info.name, name) == 0)
            return (int)i;
    return -1;
}

int lpv_hard_case_build(const char *name, lpv_hard_scene *out)
{
    memset(out, 0, sizeof *out);
    default_camera(out);
    int i = lpv_hard_case_find(name);
    if (i < 0 || CASES[i].build(out) != 0) {
        lpv_hard_scene_free(out);
        return -1;
    }
    snprintf(out->scene.source, sizeof out->scene.source, "hard-case:%s", name);
    lpv_scene_compute_bounds(&out->scene);
    return 0;
}

int lpv_hard_case_view(const lpv_hard_scene *h, int width, int height, lpv_view *out)
{
    return lpv_view_look_at(h->eye, h->target, h->yfov, width, height, out);
}

void lpv_hard_scene_free(lpv_hard_scene *h)
{
    lpv_scene_free(&h->scene);
    memset(h, 0, sizeof *h);
}
