/* scene_defaults.c - see scene_defaults.h. The rules, in words, are in
 * docs/scenes.md ("Defaults"); every distance is a fraction of the scene's
 * diagonal S or of distances measured by rays. */
#include "scene_defaults.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "raycast.h"

#define PROBE_RAYS 64        /* directions per probe (a Fibonacci sphere) */
#define LATTICE 5            /* candidate eye points per axis of the bounds */
#define ENCLOSED_HITS 0.97f  /* a candidate is enclosed when this fraction of its rays hit */
#define ROOM_SIZE 0.02f      /* ... and its mean free distance is at least this x S (not a gap between parts) */
#define KEY_SHARE 0.95f      /* the first light candidate lighting this share of the best one's points wins */
#define AZIMUTHS 16          /* view directions tried from an interior eye */
#define FAN 5                /* rays per side of the fan that scores a view direction */
#define LIGHT_RAYS 16        /* visible points per side sampled for the light */
#define DEFAULT_YFOV 0.785398f /* 45 degrees */
#define LONG_RATIO 4.0f      /* a long scene: its longest horizontal side is at least this x each other side */
#define ALONG 9              /* candidate eye points along a long scene's long axis */
#define WALLED 0.9f          /* a corridor candidate: this share of its rays below SIDE_Y hit */
#define SIDE_Y 0.2f          /* direction y under this: at most 11.5 degrees above the horizon */
#define LEAVE_TRIES 8        /* surfaces the eye may step through to leave closed geometry */

static const float GOLDEN = 2.39996323f; /* pi (3 - sqrt 5) */

typedef struct probe {
    int hits, back;
    int side_rays, side_hits; /* the rays under SIDE_Y: walls around, whether the sky is open or not */
    float mean, min;
} probe;

static float dot3(const float a[3], const float b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const float a[3], const float b[3], float o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static void norm3(float v[3])
{
    float l = sqrtf(dot3(v, v));
    if (l > 0.0f && isfinite(l))
        for (int i = 0; i < 3; ++i)
            v[i] /= l;
}

static void fib_dir(int i, int n, float d[3])
{
    float z = 1.0f - (2.0f * (float)i + 1.0f) / (float)n;
    float r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
    float phi = GOLDEN * (float)i;
    d[0] = r * cosf(phi);
    d[1] = z;
    d[2] = r * sinf(phi);
}

typedef struct ctx {
    const lpv_scene *s;
    lpv_raycast *rc;
    float lo[3], hi[3], centre[3];
    float size; /* S: the bounds' diagonal (1 when empty) */
    float eps;  /* ray offset, 1e-5 S */
} ctx;

static probe probe_point(const ctx *c, const float p[3])
{
    probe pr = {0, 0, 0, 0, 0.0f, INFINITY};
    double sum = 0.0;
    for (int i = 0; i < PROBE_RAYS; ++i) {
        float d[3], t, f[3];
        fib_dir(i, PROBE_RAYS, d);
        const int side = d[1] < SIDE_Y;
        pr.side_rays += side;
        if (!lpv_raycast_hit(c->rc, p, d, c->eps, INFINITY, &t, f))
            continue;
        pr.hits++;
        pr.side_hits += side;
        sum += t;
        pr.min = fminf(pr.min, t);
        if (dot3(f, d) > 0.0f)
            pr.back++;
    }
    pr.mean = pr.hits ? (float)(sum / pr.hits) : 0.0f;
    return pr;
}

static int probe_inside(const probe *p)
{
    return p->hits > 0 && 2 * p->back > p->hits;
}

static int ctx_init(ctx *c, const lpv_scene *s, char *err, size_t n)
{
    memset(c, 0, sizeof *c);
    c->s = s;
    float d2 = 0.0f;
    for (int i = 0; i < 3; ++i) {
        c->lo[i] = isfinite(s->bounds_min[i]) ? s->bounds_min[i] : 0.0f;
        c->hi[i] = isfinite(s->bounds_max[i]) ? s->bounds_max[i] : 0.0f;
        c->centre[i] = 0.5f * (c->lo[i] + c->hi[i]);
        d2 += (c->hi[i] - c->lo[i]) * (c->hi[i] - c->lo[i]);
    }
    c->size = sqrtf(d2);
    if (!(c->size > 0.0f) || !isfinite(c->size))
        c->size = 1.0f;
    c->eps = 1e-5f * c->size;
    return lpv_raycast_create(s, &c->rc, err, n);
}

int lpv_defaults_inside_solid(const lpv_scene *s, const float p[3])
{
    ctx c;
    char err[256];
    if (ctx_init(&c, s, err, sizeof err) != 0)
        return 0;
    probe pr = probe_point(&c, p);
    lpv_raycast_destroy(c.rc);
    return probe_inside(&pr);
}

/* A 45-degree camera at eye looking along f (unit), up from world +Y. */
static void set_camera(lpv_camera *cam, const float eye[3], const float f[3])
{
    memset(cam, 0, sizeof *cam);
    snprintf(cam->name, sizeof cam->name, "default");
    cam->yfov = DEFAULT_YFOV;
    memcpy(cam->eye, eye, sizeof cam->eye);
    memcpy(cam->forward, f, sizeof cam->forward);
    if (fabsf(f[1]) > 0.999f)
        cam->up[2] = -1.0f;
    else
        cam->up[1] = 1.0f;
}

/* Sum of hit distances over a FAN x FAN fan of rays inside the view cone: how
 * much the view from eye along f sees (a miss sees nothing). */
static float view_content(const ctx *c, const float eye[3], const float f[3])
{
    float up[3] = {0.0f, 1.0f, 0.0f}, r[3], u[3];
    cross3(f, up, r);
    norm3(r);
    cross3(r, f, u);
    float tn = tanf(0.5f * DEFAULT_YFOV), sum = 0.0f;
    for (int j = 0; j < FAN; ++j)
        for (int i = 0; i < FAN; ++i) {
            float sx = (2.0f * ((float)i + 0.5f) / FAN - 1.0f) * tn, sy = (2.0f * ((float)j + 0.5f) / FAN - 1.0f) * tn;
            float d[3], t;
            for (int k = 0; k < 3; ++k)
                d[k] = f[k] + sx * r[k] + sy * u[k];
            norm3(d);
            if (lpv_raycast_hit(c->rc, eye, d, c->eps, INFINITY, &t, NULL))
                sum += t;
        }
    return sum;
}

/* Steps the eye at p halfway back towards the surface behind it (seen
 * along -f), so the view takes in more, and makes it the camera. */
static void step_back_and_set(const ctx *c, lpv_camera *cam, float p[3], const float f[3])
{
    float back[3] = {-f[0], -f[1], -f[2]}, t;
    if (lpv_raycast_hit(c->rc, p, back, c->eps, INFINITY, &t, NULL))
        for (int a = 0; a < 3; ++a)
            p[a] += 0.5f * t * back[a];
    set_camera(cam, p, f);
}

/* Inside an enclosed scene: the lattice point with the most open space around
 * it (largest mean free distance) among those whose rays nearly all hit
 * front faces, looking where the most content is, stepped back half-way to
 * what is behind it. Returns 0 when no lattice point is enclosed. */
static int interior_camera(const ctx *c, lpv_camera *cam)
{
    float best[3] = {0}, best_mean = 0.0f;
    int found = 0;
    for (int k = 0; k < LATTICE; ++k)
        for (int j = 0; j < LATTICE; ++j)
            for (int i = 0; i < LATTICE; ++i) {
                float p[3];
                int idx[3] = {i, j, k};
                for (int a = 0; a < 3; ++a)
                    p[a] = c->lo[a] + ((float)idx[a] + 0.5f) / LATTICE * (c->hi[a] - c->lo[a]);
                probe pr = probe_point(c, p);
                if ((float)pr.hits < ENCLOSED_HITS * PROBE_RAYS || 8 * pr.back > pr.hits ||
                    !(pr.min > 0.1f * pr.mean) || !(pr.mean > ROOM_SIZE * c->size))
                    continue;
                if (!found || pr.mean > best_mean) {
                    memcpy(best, p, sizeof best);
                    best_mean = pr.mean;
                    found = 1;
                }
            }
    if (!found)
        return 0;
    float best_f[3] = {0.0f, 0.0f, -1.0f}, best_score = -1.0f;
    for (int a = 0; a < AZIMUTHS; ++a) {
        float phi = 6.28318531f * (float)a / AZIMUTHS, el = -0.15f;
        float f[3] = {cosf(el) * sinf(phi), sinf(el), -cosf(el) * cosf(phi)};
        float score = view_content(c, best, f);
        if (score > best_score) {
            best_score = score;
            memcpy(best_f, f, sizeof best_f);
        }
    }
    step_back_and_set(c, cam, best, best_f);
    return 1;
}

/* A long scene (a tunnel, a street) or a roofless one: the lattice point
 * (ALONG points along the horizontal axis `axis`, LATTICE x LATTICE across
 * it) that is not inside closed geometry, has walls around it (WALLED of its
 * rays below SIDE_Y hit, few of them back faces) and keeps the most room
 * to the nearest surface (the middle of the cross-section; nearer the middle
 * of the axis on a tie); looking along the axis, level or slightly down,
 * whichever sees the most, stepped back half-way to what is behind it. From
 * outside, a long scene is a line across the frame (issue 30: a 479 m x 2 m
 * tunnel covered 0.3 % of it). Returns 0 when no point qualifies. */
static int corridor_camera(const ctx *c, int axis, lpv_camera *cam)
{
    const int o1 = axis == 0 ? 1 : 0, o2 = axis == 2 ? 1 : 2;
    const float shortest = fminf(c->hi[o1] - c->lo[o1], c->hi[o2] - c->lo[o2]);
    float best[3] = {0}, best_score = -INFINITY;
    int found = 0;
    for (int k = 0; k < ALONG; ++k)
        for (int j = 0; j < LATTICE; ++j)
            for (int i = 0; i < LATTICE; ++i) {
                float p[3];
                const float fa = ((float)k + 0.5f) / ALONG;
                p[axis] = c->lo[axis] + fa * (c->hi[axis] - c->lo[axis]);
                p[o1] = c->lo[o1] + ((float)i + 0.5f) / LATTICE * (c->hi[o1] - c->lo[o1]);
                p[o2] = c->lo[o2] + ((float)j + 0.5f) / LATTICE * (c->hi[o2] - c->lo[o2]);
                probe pr = probe_point(c, p);
                if (probe_inside(&pr) || (float)pr.side_hits < WALLED * (float)pr.side_rays || 8 * pr.back > pr.hits ||
                    !(pr.min > 0.05f * shortest)) /* not in a gap between parts */
                    continue;
                const float score = pr.min * (1.0f - 0.01f * fabsf(fa - 0.5f));
                if (!found || score > best_score) {
                    memcpy(best, p, sizeof best);
                    best_score = score;
                    found = 1;
                }
            }
    if (!found)
        return 0;
    float best_f[3] = {0}, best_content = -1.0f;
    static const float ELEVATIONS[2] = {0.0f, -0.15f};
    for (int sgn = 0; sgn < 2; ++sgn)
        for (int e = 0; e < 2; ++e) {
            float f[3] = {0.0f, sinf(ELEVATIONS[e]), 0.0f};
            f[axis] = (sgn ? -1.0f : 1.0f) * cosf(ELEVATIONS[e]);
            const float content = view_content(c, best, f);
            if (content > best_content) {
                best_content = content;
                memcpy(best_f, f, sizeof best_f);
            }
        }
    step_back_and_set(c, cam, best, best_f);
    return 1;
}

/* The scene's long horizontal axis (0 = x, 2 = z) when one is at least
 * LONG_RATIO x each other side of the bounds, else -1. */
static int long_axis(const ctx *c)
{
    float e[3];
    for (int a = 0; a < 3; ++a)
        e[a] = c->hi[a] - c->lo[a];
    for (int a = 0; a < 3; a += 2)
        if (e[a] >= LONG_RATIO * e[2 - a] && e[a] >= LONG_RATIO * e[1])
            return a;
    return -1;
}

/* Moves an eye that stands inside closed geometry (probe_inside) forward
 * through the surfaces that close it in (each the first hit ahead), at most
 * LEAVE_TRIES of them. Returns 0 when the eye ends outside, else -1. */
static int leave_solid(const ctx *c, lpv_camera *cam)
{
    float f[3];
    memcpy(f, cam->forward, sizeof f);
    norm3(f);
    for (int k = 0; k < LEAVE_TRIES; ++k) {
        probe pr = probe_point(c, cam->eye);
        if (!probe_inside(&pr))
            return 0;
        float t;
        if (!lpv_raycast_hit(c->rc, cam->eye, f, c->eps, INFINITY, &t, NULL))
            return -1;
        for (int a = 0; a < 3; ++a)
            cam->eye[a] += (t + 100.0f * c->eps) * f[a];
    }
    probe pr = probe_point(c, cam->eye);
    return probe_inside(&pr) ? -1 : 0;
}

/* An object or open scene: a three-quarter view from the front (+Z, glTF's
 * front), the right and above, at the smallest distance that keeps all eight
 * corners of the bounds in a square 45-degree frame, plus 5 %. */
static void framing_camera(const ctx *c, lpv_camera *cam)
{
    float D[3] = {0.45f, 0.42f, 0.79f}, f[3];
    norm3(D);
    for (int a = 0; a < 3; ++a)
        f[a] = -D[a];
    float up[3] = {0.0f, 1.0f, 0.0f}, r[3], u[3];
    cross3(f, up, r);
    norm3(r);
    cross3(r, f, u);
    float tn = tanf(0.5f * DEFAULT_YFOV), dist = 0.0f;
    for (int k = 0; k < 8; ++k) {
        float p[3];
        for (int a = 0; a < 3; ++a)
            p[a] = ((k >> a) & 1 ? c->hi[a] : c->lo[a]) - c->centre[a];
        float along = dot3(p, D);
        dist = fmaxf(dist, along + fabsf(dot3(p, r)) / tn);
        dist = fmaxf(dist, along + fabsf(dot3(p, u)) / tn);
    }
    if (!(dist > 0.0f) || !isfinite(dist))
        dist = c->size;
    dist *= 1.05f;
    float eye[3];
    for (int a = 0; a < 3; ++a)
        eye[a] = c->centre[a] + D[a] * dist;
    set_camera(cam, eye, f);
}

static int add_camera(lpv_scene *s, const ctx *c)
{
    lpv_camera *cams = realloc(s->cameras, ((size_t)s->camera_count + 1) * sizeof *cams);
    if (!cams)
        return -1;
    s->cameras = cams;
    lpv_camera *cam = &cams[s->camera_count];
    /* a long scene first: seen from outside it is a line across the frame */
    const int along = long_axis(c);
    const float ex = c->hi[0] - c->lo[0], ez = c->hi[2] - c->lo[2];
    if (!(along >= 0 && corridor_camera(c, along, cam)) && !interior_camera(c, cam) &&
        !corridor_camera(c, ex >= ez ? 0 : 2, cam)) /* roofless: walls around, open sky */
        framing_camera(c, cam);
    /* never inside closed geometry: step out ahead, else frame from outside
     * (outside the bounds, so outside every closed mesh) */
    if (leave_solid(c, cam) != 0)
        framing_camera(c, cam);
    s->camera_count++;
    s->default_camera_added = 1;
    return 0;
}

typedef struct seen {
    float p[3], n[3]; /* n: the side facing the camera */
    float t;
} seen;

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* The camera's unit forward f, right r = f x up and up u = r x f. */
static void camera_basis(const lpv_camera *cam, float f[3], float r[3], float u[3])
{
    float up[3];
    memcpy(f, cam->forward, 3 * sizeof *f);
    memcpy(up, cam->up, sizeof up);
    norm3(f);
    cross3(f, up, r);
    norm3(r);
    cross3(r, f, u);
}

/* The surface points camera 0 sees through LIGHT_RAYS^2 pixel rays. */
static size_t visible_points(const ctx *c, const lpv_camera *cam, seen *out)
{
    float f[3], r[3], u[3];
    camera_basis(cam, f, r, u);
    float aspect = cam->aspect > 0.0f ? cam->aspect : 1.0f;
    float ty = cam->orthographic ? (cam->ymag > 0.0f ? cam->ymag : 1.0f) : tanf(0.5f * (cam->yfov > 0.0f ? cam->yfov : 0.8f));
    size_t n = 0;
    for (int j = 0; j < LIGHT_RAYS; ++j)
        for (int i = 0; i < LIGHT_RAYS; ++i) {
            float sx = (2.0f * ((float)i + 0.5f) / LIGHT_RAYS - 1.0f) * ty * aspect;
            float sy = (2.0f * ((float)j + 0.5f) / LIGHT_RAYS - 1.0f) * ty;
            float o[3], d[3], t, fr[3];
            for (int k = 0; k < 3; ++k) {
                o[k] = cam->eye[k] + (cam->orthographic ? sx * r[k] + sy * u[k] : 0.0f);
                d[k] = cam->orthographic ? f[k] : f[k] + sx * r[k] + sy * u[k];
            }
            norm3(d);
            if (!lpv_raycast_hit(c->rc, o, d, c->eps, INFINITY, &t, fr))
                continue;
            seen *sp = &out[n++];
            float flip = dot3(fr, d) > 0.0f ? -1.0f : 1.0f;
            for (int k = 0; k < 3; ++k) {
                sp->p[k] = o[k] + t * d[k];
                sp->n[k] = flip * fr[k];
            }
            sp->t = t;
        }
    return n;
}

/* How many of the visible points the light at L reaches unblocked, at more
 * than grazing incidence (cos > 0.05). */
static float light_score(const ctx *c, const seen *pts, size_t n, const float L[3])
{
    float score = 0.0f;
    for (size_t i = 0; i < n; ++i) {
        float d[3], o[3];
        for (int k = 0; k < 3; ++k)
            d[k] = L[k] - pts[i].p[k];
        float len = sqrtf(dot3(d, d));
        if (!(len > c->eps))
            continue;
        for (int k = 0; k < 3; ++k)
            d[k] /= len;
        float cosn = dot3(d, pts[i].n);
        if (!(cosn > 0.05f))
            continue;
        for (int k = 0; k < 3; ++k)
            o[k] = pts[i].p[k] + 10.0f * c->eps * pts[i].n[k];
        if (!lpv_raycast_hit(c->rc, o, d, 0.0f, len - 10.0f * c->eps, NULL, NULL))
            score += 1.0f;
    }
    return score;
}

/* The light: candidate positions offset from camera 0 up and to either side
 * (a key light), by 1, 1/2, 1/4 of the median distance to what it sees, and
 * the eye itself; a candidate must be reachable from the eye without crossing
 * a surface and not inside closed geometry. Each is scored by how many of the
 * camera's visible points it lights (unshadowed, cos > 0.05); the first in
 * that order lighting at least KEY_SHARE of the best score wins. Its intensity
 * gives 1 W/m^2 (facing the light) at the median distance to the points it
 * lights. */
static int add_light(lpv_scene *s, const ctx *c)
{
    lpv_light *lights = realloc(s->lights, ((size_t)s->light_count + 1) * sizeof *lights);
    if (!lights)
        return -1;
    s->lights = lights;
    seen *pts = malloc(LIGHT_RAYS * LIGHT_RAYS * sizeof *pts);
    float *dist = malloc(LIGHT_RAYS * LIGHT_RAYS * sizeof *dist);
    if (!pts || !dist) {
        free(pts);
        free(dist);
        return -1;
    }
    const lpv_camera *cam = &s->cameras[0];
    size_t n = visible_points(c, cam, pts);
    for (size_t i = 0; i < n; ++i)
        dist[i] = pts[i].t;
    qsort(dist, n, sizeof *dist, cmp_float);
    float dmed = n ? dist[n / 2] : 0.5f * c->size;
    float f[3], r[3], u[3];
    camera_basis(cam, f, r, u);
    static const float OFFSETS[3][2] = {{0.4f, 0.3f}, {0.4f, -0.3f}, {0.4f, 0.0f}}; /* (up, right) */
    static const float SCALES[3] = {1.0f, 0.5f, 0.25f};
    float cand[10][3], score[10], best_score = 0.0f;
    int nc = 0;
    for (int k = 0; k < 10; ++k) {
        float *L = cand[nc];
        if (k < 9) {
            const float *o = OFFSETS[k % 3];
            float sc = SCALES[k / 3] * dmed;
            for (int a = 0; a < 3; ++a)
                L[a] = cam->eye[a] + sc * (o[0] * u[a] + o[1] * r[a]);
            float d[3], len2 = 0.0f;
            for (int a = 0; a < 3; ++a) {
                d[a] = L[a] - cam->eye[a];
                len2 += d[a] * d[a];
            }
            float len = sqrtf(len2);
            norm3(d);
            if (lpv_raycast_hit(c->rc, cam->eye, d, 0.0f, len, NULL, NULL))
                continue; /* behind a wall from the camera */
            probe pr = probe_point(c, L);
            if (probe_inside(&pr))
                continue;
        } else {
            memcpy(L, cam->eye, 3 * sizeof(float));
        }
        score[nc] = light_score(c, pts, n, L);
        best_score = fmaxf(best_score, score[nc]);
        nc++;
    }
    /* a key light beside the camera rather than a flat headlight, unless it
     * lights clearly less of the view */
    float best[3];
    for (int k = 0; k < nc; ++k)
        if (score[k] >= KEY_SHARE * best_score) {
            memcpy(best, cand[k], sizeof best);
            break;
        }
    size_t m = 0;
    for (size_t i = 0; i < n; ++i) {
        float d[3];
        for (int a = 0; a < 3; ++a)
            d[a] = best[a] - pts[i].p[a];
        if (dot3(d, pts[i].n) > 0.0f)
            dist[m++] = sqrtf(dot3(d, d));
    }
    qsort(dist, m, sizeof *dist, cmp_float);
    float dl = m ? dist[m / 2] : dmed;
    if (!(dl > 0.0f) || !isfinite(dl))
        dl = c->size;
    free(pts);
    free(dist);

    lpv_light *l = &lights[s->light_count];
    memset(l, 0, sizeof *l);
    l->type = LPV_LIGHT_POINT;
    snprintf(l->name, sizeof l->name, "default");
    l->color[0] = l->color[1] = l->color[2] = 1.0f;
    l->intensity = dl * dl * 1.0f; /* W/sr: E = I / d^2 = 1 W/m^2 at the median lit distance */
    memcpy(l->position, best, sizeof l->position);
    l->direction[1] = -1.0f;
    s->light_count++;
    s->default_light_added = 1;
    return 0;
}

int lpv_scene_add_defaults(lpv_scene *s, char *err, size_t n)
{
    int need_camera = s->camera_count == 0;
    int need_light = s->light_count == 0 && lpv_scene_emissive_draw_count(s) == 0;
    if (!need_camera && !need_light)
        return 0;
    ctx c;
    if (ctx_init(&c, s, err, n) != 0)
        return -1;
    int rc = 0;
    if (need_camera && add_camera(s, &c) != 0)
        rc = -1;
    if (rc == 0 && need_light && add_light(s, &c) != 0)
        rc = -1;
    lpv_raycast_destroy(c.rc);
    if (rc != 0)
        snprintf(err, n, "%s: out of memory adding the default camera or light", s->source);
    return rc;
}
