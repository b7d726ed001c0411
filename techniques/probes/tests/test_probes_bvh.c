/*
 * test_probes_bvh.c - the probes' BVH (techniques/probes/core/probes_bvh.h),
 * the CPU oracle a future GLSL traversal will be held to:
 *
 * - closest hit: over a random triangle soup and random rays (some axis
 *   aligned, some not unit, some short), the traversal finds the same
 *   triangle at the same t as brute force over every triangle, and misses
 *   where it misses; copies of one triangle resolve to the lowest id;
 * - exactness: from inside a closed box every ray hits, at the analytic
 *   distance to the wall it leaves by, and not at all when tmax falls short;
 * - structure: node 0 is the root, every node is reached exactly once, left
 *   children follow their parents, every box is exactly the union of its
 *   children's (a leaf's: of its triangles' corners), every kept triangle
 *   is in exactly one leaf, the vertex array is the input's corners in
 *   triangle order, the tree fits the traversal's stack, and two builds of
 *   one input are byte for byte the same;
 * - bad input: an index out of range is refused, naming the triangle;
 *   triangles with a NaN or infinite corner or no area are left out and
 *   never hit; no triangles (or none left) is one empty leaf that nothing
 *   hits; building and freeing many times leaks nothing (under ASan).
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

#include "probes_bvh.h"

static uint32_t rng_state = 20261207u;
static float rnd(void)
{
    rng_state = rng_state * 1664525u + 1013904223u;
    return (float)(rng_state >> 8) / 16777216.0f;
}

typedef struct mesh {
    float *pos;
    size_t vertex_count;
    uint32_t *idx;
    size_t triangle_count;
} mesh;

static void mesh_free(mesh *m)
{
    free(m->pos);
    free(m->idx);
    memset(m, 0, sizeof *m);
}

/* n small triangles (corners within 0.075 of a centre) in the unit cube; each
 * has its own 3 vertices, but the vertex array is shuffled so the indices
 * are not 0, 1, 2, ... */
static mesh soup(size_t n)
{
    mesh m = {malloc(9 * n * sizeof(float)), 3 * n, malloc(3 * n * sizeof(uint32_t)), n};
    assert_non_null(m.pos);
    assert_non_null(m.idx);
    uint32_t *perm = malloc(3 * n * sizeof *perm);
    assert_non_null(perm);
    for (size_t i = 0; i < 3 * n; i++)
        perm[i] = (uint32_t)i;
    for (size_t i = 3 * n - 1; i > 0; i--) {
        size_t j = (size_t)(rnd() * (float)(i + 1));
        if (j > i)
            j = i;
        uint32_t s = perm[i];
        perm[i] = perm[j];
        perm[j] = s;
    }
    for (size_t t = 0; t < n; t++) {
        float c[3] = {rnd(), rnd(), rnd()};
        for (int k = 0; k < 3; k++) {
            uint32_t v = perm[3 * t + (size_t)k];
            m.idx[3 * t + (size_t)k] = v;
            for (int a = 0; a < 3; a++)
                m.pos[3 * v + (size_t)a] = c[a] + (rnd() - 0.5f) * 0.15f;
        }
    }
    free(perm);
    return m;
}

static const float *corner(const mesh *m, size_t t, int k) { return m->pos + 3 * (size_t)m->idx[3 * t + (size_t)k]; }

/* The closest hit over every triangle but those in skip (may be NULL), by
 * the same triangle test and the same tie rule as the traversal. */
static int brute(const mesh *m, const unsigned char *skip, const float o[3], const float d[3], float tmax, float *t_out,
                 uint32_t *tri_out)
{
    int hit = 0;
    float best = tmax;
    uint32_t best_tri = 0;
    for (size_t t = 0; t < m->triangle_count; t++) {
        if (skip && skip[t])
            continue;
        float th;
        if (lpv_probes_bvh_ray_triangle(o, d, corner(m, t, 0), corner(m, t, 1), corner(m, t, 2), tmax, &th) &&
            (!hit || th < best)) {
            best = th;
            best_tri = (uint32_t)t;
            hit = 1;
        }
    }
    *t_out = best;
    *tri_out = best_tri;
    return hit;
}

static void random_dir(float d[3], int i)
{
    for (;;) {
        for (int a = 0; a < 3; a++)
            d[a] = rnd() * 2.0f - 1.0f;
        float l2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        if (l2 > 0.01f && l2 <= 1.0f)
            break;
    }
    if (i % 7 == 0) { /* along one axis: two 1 / dir are the guarded kind */
        int a = (i / 7) % 3;
        float s = d[a] < 0.0f ? -1.0f : 1.0f;
        d[0] = d[1] = d[2] = 0.0f;
        d[a] = s;
    } else if (i % 11 == 0) { /* in an axis plane */
        d[(i / 11) % 3] = 0.0f;
    }
    if (i % 5 == 0) { /* not unit: t is in dir's units */
        float s = 0.1f + 10.0f * rnd();
        for (int a = 0; a < 3; a++)
            d[a] *= s;
    }
}

static int same_bits(float a, float b) { return memcmp(&a, &b, sizeof a) == 0; }

/* ---- Structure ------------------------------------------------------------------ */

static void check_structure(const lpv_probes_bvh *b, const mesh *m, const unsigned char *skip)
{
    assert_true(b->node_count >= 1);
    assert_true(b->depth >= 1 && b->depth <= LPV_PROBES_BVH_MAX_DEPTH);
    assert_int_equal(b->triangle_count, m->triangle_count);
    size_t skipped = 0;
    for (size_t t = 0; t < m->triangle_count; t++)
        skipped += skip && skip[t];
    assert_int_equal(b->skipped, skipped);
    assert_int_equal(b->leaf_tri_count, m->triangle_count - skipped);

    /* the vertex array: the input's corners in triangle order, w = 0 */
    for (size_t t = 0; t < m->triangle_count; t++)
        for (int k = 0; k < 3; k++) {
            const float *v = b->vertices + 12 * t + 4 * (size_t)k, *p = corner(m, t, k);
            for (int a = 0; a < 3; a++)
                assert_true(same_bits(v[a], p[a]));
            assert_true(v[3] == 0.0f);
        }

    unsigned *seen_node = calloc(b->node_count, sizeof *seen_node);
    unsigned *seen_tri = calloc(m->triangle_count + 1, sizeof *seen_tri);
    assert_non_null(seen_node);
    assert_non_null(seen_tri);
    /* walk from node 0, recording each node's level */
    size_t *todo = malloc(b->node_count * sizeof *todo);
    unsigned *level = malloc(b->node_count * sizeof *level);
    assert_non_null(todo);
    assert_non_null(level);
    size_t ntodo = 0, leaf_entries = 0;
    unsigned deepest = 0;
    float root_lo[3] = {INFINITY, INFINITY, INFINITY}, root_hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    todo[ntodo++] = 0;
    level[0] = 1;
    while (ntodo > 0) {
        size_t i = todo[--ntodo];
        assert_true(i < b->node_count);
        assert_int_equal(seen_node[i], 0);
        seen_node[i]++;
        if (level[i] > deepest)
            deepest = level[i];
        const lpv_probes_bvh_node *n = &b->nodes[i];
        if (n->b & LPV_PROBES_BVH_LEAF) {
            uint32_t count = n->b & LPV_PROBES_BVH_COUNT_MASK;
            assert_true(count <= LPV_PROBES_BVH_LEAF_SIZE);
            assert_true((size_t)n->a + count <= b->leaf_tri_count);
            leaf_entries += count;
            if (b->leaf_tri_count == 0) /* the empty tree's one leaf */
                continue;
            assert_true(count >= 1);
            /* the leaf's box is exactly its triangles' corners' */
            float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
            for (uint32_t e = 0; e < count; e++) {
                uint32_t t = b->leaf_tris[n->a + e];
                assert_true(t < m->triangle_count);
                assert_false(skip && skip[t]);
                seen_tri[t]++;
                for (int k = 0; k < 3; k++)
                    for (int a = 0; a < 3; a++) {
                        float c = corner(m, t, k)[a];
                        lo[a] = fminf(lo[a], c);
                        hi[a] = fmaxf(hi[a], c);
                        root_lo[a] = fminf(root_lo[a], c);
                        root_hi[a] = fmaxf(root_hi[a], c);
                    }
            }
            for (int a = 0; a < 3; a++) {
                assert_true(n->lo[a] == lo[a]);
                assert_true(n->hi[a] == hi[a]);
            }
        } else {
            assert_int_equal(n->b, 0);
            size_t l = i + 1, r = n->a;
            assert_true(l < b->node_count);
            assert_true(r > l && r < b->node_count);
            /* exactly the union of the children's boxes: tight, and so
             * containing each */
            const lpv_probes_bvh_node *cl = &b->nodes[l], *cr = &b->nodes[r];
            for (int a = 0; a < 3; a++) {
                assert_true(cl->lo[a] >= n->lo[a] && cl->hi[a] <= n->hi[a]);
                assert_true(cr->lo[a] >= n->lo[a] && cr->hi[a] <= n->hi[a]);
                assert_true(n->lo[a] == fminf(cl->lo[a], cr->lo[a]));
                assert_true(n->hi[a] == fmaxf(cl->hi[a], cr->hi[a]));
            }
            level[l] = level[r] = level[i] + 1;
            todo[ntodo++] = r;
            todo[ntodo++] = l;
        }
    }
    for (size_t i = 0; i < b->node_count; i++)
        assert_int_equal(seen_node[i], 1); /* every node reached from node 0, once */
    assert_int_equal(leaf_entries, b->leaf_tri_count);
    assert_int_equal(deepest, b->depth);
    for (size_t t = 0; t < m->triangle_count; t++)
        assert_int_equal(seen_tri[t], (skip && skip[t]) ? 0 : 1);
    if (b->leaf_tri_count > 0)
        for (int a = 0; a < 3; a++) {
            assert_true(b->nodes[0].lo[a] == root_lo[a]);
            assert_true(b->nodes[0].hi[a] == root_hi[a]);
        }
    free(level);
    free(todo);
    free(seen_tri);
    free(seen_node);
}

/* ---- (a) closest hit against brute force ------------------------------------------- */

static void test_soup_matches_brute_force(void **state)
{
    (void)state;
    mesh m = soup(2000);
    lpv_probes_bvh b;
    char err[256] = "";
    assert_int_equal(lpv_probes_bvh_build(&b, m.pos, m.vertex_count, m.idx, m.triangle_count, err, sizeof err), 0);
    check_structure(&b, &m, NULL);

    int hits = 0, misses = 0, short_misses = 0;
    for (int i = 0; i < 5000; i++) {
        float o[3] = {rnd() * 1.5f - 0.25f, rnd() * 1.5f - 0.25f, rnd() * 1.5f - 0.25f}, d[3];
        random_dir(d, i);
        /* a third with a short reach, so tmax cuts some hits off */
        float tmax = i % 3 == 0 ? 0.05f + 0.3f * rnd() : (i % 3 == 1 ? INFINITY : 1e30f);
        float tb = 0.0f, tv = 0.0f;
        uint32_t rb = 0, rv = 0;
        int hb = brute(&m, NULL, o, d, tmax, &tb, &rb);
        int hv = lpv_probes_bvh_intersect(&b, o, d, tmax, &tv, &rv);
        if (hb != hv || (hb && (rb != rv || fabsf(tv - tb) > 1e-5f * tb)))
            fail_msg("ray %d: brute force %d (tri %u, t %.9g), BVH %d (tri %u, t %.9g)", i, hb, rb, (double)tb, hv, rv,
                     (double)tv);
        if (hb)
            hits++;
        else {
            misses++;
            if (i % 3 == 0 && brute(&m, NULL, o, d, INFINITY, &tb, &rb))
                short_misses++;
        }
        /* the outputs are optional */
        assert_int_equal(lpv_probes_bvh_intersect(&b, o, d, tmax, NULL, NULL), hv);
    }
    print_message("soup: %zu nodes, depth %u, %d hits, %d misses (%d only for tmax)\n", b.node_count, b.depth, hits,
                  misses, short_misses);
    /* the comparison means something only if both outcomes are common */
    assert_true(hits > 1000);
    assert_true(misses > 500);
    assert_true(short_misses > 50);

    /* one input, one tree: the same bytes */
    lpv_probes_bvh b2;
    assert_int_equal(lpv_probes_bvh_build(&b2, m.pos, m.vertex_count, m.idx, m.triangle_count, err, sizeof err), 0);
    assert_int_equal(b2.node_count, b.node_count);
    assert_memory_equal(b2.nodes, b.nodes, b.node_count * sizeof *b.nodes);
    assert_memory_equal(b2.leaf_tris, b.leaf_tris, b.leaf_tri_count * sizeof *b.leaf_tris);
    lpv_probes_bvh_free(&b2);

    lpv_probes_bvh_free(&b);
    lpv_probes_bvh_free(&b); /* freed twice: fine, it was zeroed */
    mesh_free(&m);
}

/* Copies of one triangle (Embree cannot split them apart by their centres)
 * among a few others: structure holds, and a ray through them finds the
 * lowest id of the copies whatever leaf each copy landed in. */
static void test_identical_triangles_lowest_id_wins(void **state)
{
    (void)state;
    enum { COPIES = 300, OTHERS = 40 };
    mesh m = soup(OTHERS + COPIES);
    /* triangles OTHERS.. keep their own vertices, all set to one shape,
     * away from the soup */
    const float shape[3][3] = {{2.0f, 2.0f, 2.0f}, {3.0f, 2.0f, 2.0f}, {2.0f, 3.0f, 2.5f}};
    for (size_t t = OTHERS; t < OTHERS + COPIES; t++)
        for (int k = 0; k < 3; k++)
            memcpy(m.pos + 3 * (size_t)m.idx[3 * t + (size_t)k], shape[k], sizeof shape[k]);
    lpv_probes_bvh b;
    char err[256] = "";
    assert_int_equal(lpv_probes_bvh_build(&b, m.pos, m.vertex_count, m.idx, m.triangle_count, err, sizeof err), 0);
    check_structure(&b, &m, NULL);
    for (int i = 0; i < 200; i++) {
        /* a point inside the shape, a ray to it from above or below */
        float u = rnd() * 0.5f, v = rnd() * 0.4f;
        float p[3];
        for (int a = 0; a < 3; a++)
            p[a] = shape[0][a] + u * (shape[1][a] - shape[0][a]) + v * (shape[2][a] - shape[0][a]);
        float o[3] = {p[0] + (rnd() - 0.5f), p[1] + (rnd() - 0.5f), p[2] + (i % 2 ? 2.0f : -2.0f)};
        float d[3] = {p[0] - o[0], p[1] - o[1], p[2] - o[2]};
        float t;
        uint32_t tri;
        assert_int_equal(lpv_probes_bvh_intersect(&b, o, d, INFINITY, &t, &tri), 1);
        assert_int_equal(tri, OTHERS);
        float tb;
        uint32_t rb;
        assert_int_equal(brute(&m, NULL, o, d, INFINITY, &tb, &rb), 1);
        assert_int_equal(rb, OTHERS);
        assert_true(t == tb);
    }
    lpv_probes_bvh_free(&b);
    mesh_free(&m);
}

/* ---- (b) inside a box ----------------------------------------------------------------- */

static void test_box_from_inside(void **state)
{
    (void)state;
    const float lo[3] = {-1.0f, -0.5f, 0.0f}, hi[3] = {2.0f, 0.5f, 3.0f};
    float pos[8 * 3];
    for (int c = 0; c < 8; c++)
        for (int a = 0; a < 3; a++)
            pos[3 * c + a] = (c >> a) & 1 ? hi[a] : lo[a];
    /* two triangles per face; face f = 2 axis + side, triangles 2f, 2f + 1 */
    uint32_t idx[12 * 3];
    for (int f = 0; f < 6; f++) {
        int axis = f / 2, side = f % 2, u = (axis + 1) % 3, v = (axis + 2) % 3;
        uint32_t q[4];
        for (int k = 0; k < 4; k++)
            q[k] = (uint32_t)((side << axis) | ((k & 1) << u) | (((k >> 1) & 1) << v));
        const uint32_t tris[6] = {q[0], q[1], q[3], q[0], q[3], q[2]};
        memcpy(idx + 6 * f, tris, sizeof tris);
    }
    mesh m = {pos, 8, idx, 12};
    lpv_probes_bvh b;
    char err[256] = "";
    assert_int_equal(lpv_probes_bvh_build(&b, pos, 8, idx, 12, err, sizeof err), 0);
    check_structure(&b, &m, NULL);

    for (int i = 0; i < 3000; i++) {
        float o[3], d[3];
        for (int a = 0; a < 3; a++)
            o[a] = lo[a] + (0.01f + 0.98f * rnd()) * (hi[a] - lo[a]);
        random_dir(d, i);
        /* the analytic distance: the first wall the ray reaches */
        double ta = INFINITY, second = INFINITY;
        int face = -1;
        for (int a = 0; a < 3; a++) {
            if (d[a] == 0.0f)
                continue;
            double ts = ((double)(d[a] > 0.0f ? hi[a] : lo[a]) - (double)o[a]) / (double)d[a];
            if (ts < ta) {
                second = ta;
                ta = ts;
                face = 2 * a + (d[a] > 0.0f);
            } else if (ts < second) {
                second = ts;
            }
        }
        float t;
        uint32_t tri;
        if (lpv_probes_bvh_intersect(&b, o, d, INFINITY, &t, &tri) != 1)
            fail_msg("ray %d from inside the box missed", i);
        if (fabs((double)t - ta) > 1e-5 * ta)
            fail_msg("ray %d: t %.9g, the wall is at %.9g", i, (double)t, ta);
        /* the wall it leaves by, unless it leaves near an edge */
        if (second > ta * 1.001)
            assert_int_equal((int)tri / 2, face);
        /* short of the wall: nothing */
        assert_int_equal(lpv_probes_bvh_intersect(&b, o, d, (float)(ta * 0.999), &t, &tri), 0);
    }

    /* Rays in a wall's plane (origin on it, no component across it): they
     * run inside the plane of every box face there, where 1 / 0 would make
     * the slab test NaN, and leave by another wall's edge. Whether they hit
     * that edge is the triangle test's rounding (Moller-Trumbore is not
     * watertight); the boxes must not change the answer, and a hit along
     * an axis is at the wall. */
    int plane_hits = 0;
    for (int i = 0; i < 1200; i++) {
        const int p = i % 3, q = (p + 1 + (i / 3) % 2) % 3;
        float o[3], d[3];
        for (int a = 0; a < 3; a++)
            o[a] = lo[a] + (0.01f + 0.98f * rnd()) * (hi[a] - lo[a]);
        o[p] = (i / 6) % 2 ? hi[p] : lo[p];
        if (i % 2 == 0) { /* along axis q */
            d[0] = d[1] = d[2] = 0.0f;
            d[q] = rnd() < 0.5f ? -1.0f : 1.0f;
        } else {
            random_dir(d, 1); /* 1: neither axis aligned nor scaled */
            d[p] = 0.0f;
        }
        float tv, tb;
        uint32_t rv, rb;
        int hv = lpv_probes_bvh_intersect(&b, o, d, INFINITY, &tv, &rv);
        int hb = brute(&m, NULL, o, d, INFINITY, &tb, &rb);
        if (hv != hb || (hv && (rv != rb || tv != tb)))
            fail_msg("in-plane ray %d: brute force %d (tri %u, t %.9g), BVH %d (tri %u, t %.9g)", i, hb, rb,
                     (double)tb, hv, rv, (double)tv);
        plane_hits += hv;
        if (hv && i % 2 == 0) {
            const float ta = ((d[q] > 0.0f ? hi[q] : lo[q]) - o[q]) / d[q];
            if (fabsf(tv - ta) > 1e-5f * ta)
                fail_msg("in-plane ray %d along axis %d: hit at t %.9g, the wall is at %.9g", i, q, (double)tv,
                         (double)ta);
        }
    }
    /* most do hit: the comparison above is not between two misses */
    assert_true(plane_hits > 600);

    /* Rays at points on the box's edges: where the triangle test decides a
     * ray hits (its rounding either way), the boxes around the triangle
     * must not have turned the ray away first, nor, when two walls'
     * triangles are hit at the same t, away from the lower id. (The second
     * is not promised (probes_bvh.h), but the boxes' slack for rounding
     * gives it on these rays; without that slack 32 of them went to the
     * higher id, and the boxes' entry t's are what to look at if a
     * platform's rounding makes this fail.) */
    int edge_hits = 0;
    for (int i = 0; i < 3000; i++) {
        const int a = i % 3, u = (a + 1) % 3, v = (a + 2) % 3;
        float o[3], target[3], d[3];
        for (int k = 0; k < 3; k++)
            o[k] = lo[k] + (0.01f + 0.98f * rnd()) * (hi[k] - lo[k]);
        target[a] = lo[a] + rnd() * (hi[a] - lo[a]);
        target[u] = (i / 3) % 2 ? hi[u] : lo[u];
        target[v] = (i / 6) % 2 ? hi[v] : lo[v];
        for (int k = 0; k < 3; k++)
            d[k] = target[k] - o[k];
        float tv, tb;
        uint32_t rv, rb;
        int hv = lpv_probes_bvh_intersect(&b, o, d, INFINITY, &tv, &rv);
        int hb = brute(&m, NULL, o, d, INFINITY, &tb, &rb);
        if (hv != hb || (hv && (rv != rb || tv != tb)))
            fail_msg("edge ray %d: brute force %d (tri %u, t %.9g), BVH %d (tri %u, t %.9g)", i, hb, rb, (double)tb, hv,
                     rv, (double)tv);
        edge_hits += hv;
    }
    print_message("box: %d of 1200 rays in its walls' planes and %d of 3000 at its edges hit (the rest slip between "
                  "two triangles' roundings)\n",
                  plane_hits, edge_hits);
    assert_true(edge_hits > 1500);
    lpv_probes_bvh_free(&b);
}

/* ---- (d) bad input ----------------------------------------------------------------------- */

static void test_index_out_of_range_is_refused(void **state)
{
    (void)state;
    mesh m = soup(20);
    m.idx[3 * 7 + 2] = (uint32_t)m.vertex_count; /* one past the end */
    lpv_probes_bvh b;
    memset(&b, 0xab, sizeof b); /* zeroed on failure, whatever it held */
    char err[256] = "";
    assert_int_equal(lpv_probes_bvh_build(&b, m.pos, m.vertex_count, m.idx, m.triangle_count, err, sizeof err), -1);
    print_message("refused: %s\n", err);
    assert_non_null(strstr(err, "triangle 7"));
    assert_null(b.nodes);
    assert_null(b.leaf_tris);
    assert_null(b.vertices);
    assert_int_equal(b.node_count, 0);
    lpv_probes_bvh_free(&b);

    err[0] = '\0';
    assert_int_equal(lpv_probes_bvh_build(&b, NULL, m.vertex_count, m.idx, m.triangle_count, err, sizeof err), -1);
    assert_true(err[0] != '\0');
    /* no err buffer: still -1, nothing written */
    assert_int_equal(lpv_probes_bvh_build(&b, NULL, m.vertex_count, m.idx, m.triangle_count, NULL, 0), -1);
    mesh_free(&m);
}

static void test_nonfinite_and_flat_triangles_are_never_hit(void **state)
{
    (void)state;
    mesh m = soup(300);
    unsigned char skip[300] = {0};
    /* a NaN corner, an infinite corner, all corners at one point, three
     * corners on one line */
    const size_t nan_tri = 17, inf_tri = 42, point_tri = 99, line_tri = 150;
    m.pos[3 * m.idx[3 * nan_tri + 1] + 0] = NAN;
    m.pos[3 * m.idx[3 * inf_tri + 2] + 1] = INFINITY;
    for (int k = 1; k < 3; k++)
        memcpy(m.pos + 3 * m.idx[3 * point_tri + (size_t)k], m.pos + 3 * m.idx[3 * point_tri], 3 * sizeof(float));
    /* (0.25, 0.25, 0.25), (0.5, ...), (0.75, ...): the edges' cross product
     * is exactly 0 in float */
    for (int k = 0; k < 3; k++)
        for (int a = 0; a < 3; a++)
            m.pos[3 * m.idx[3 * line_tri + (size_t)k] + (size_t)a] = 0.25f * (float)(k + 1);
    skip[nan_tri] = skip[inf_tri] = skip[point_tri] = skip[line_tri] = 1;
    lpv_probes_bvh b;
    char err[256] = "";
    assert_int_equal(lpv_probes_bvh_build(&b, m.pos, m.vertex_count, m.idx, m.triangle_count, err, sizeof err), 0);
    check_structure(&b, &m, skip);
    assert_int_equal(b.skipped, 4);

    const size_t bad[4] = {nan_tri, inf_tri, point_tri, line_tri};
    for (int i = 0; i < 2000; i++) {
        /* at a bad triangle's finite corners (and their middle), from all
         * around; and random rays, compared with brute force over the good */
        float o[3], d[3], target[3];
        if (i < 1000) {
            size_t t = bad[i % 4];
            const float *c0 = corner(&m, t, 0), *c2 = corner(&m, t, i % 4 == 1 ? 0 : 2);
            for (int a = 0; a < 3; a++) {
                target[a] = 0.5f * (c0[a] + c2[a]);
                o[a] = target[a] + (rnd() - 0.5f) * 2.0f;
                d[a] = target[a] - o[a];
            }
        } else {
            for (int a = 0; a < 3; a++)
                o[a] = rnd() * 1.5f - 0.25f;
            random_dir(d, i);
        }
        float tv, tb;
        uint32_t rv, rb;
        int hv = lpv_probes_bvh_intersect(&b, o, d, INFINITY, &tv, &rv);
        if (hv)
            for (int k = 0; k < 4; k++)
                assert_true(rv != bad[k]);
        int hb = brute(&m, skip, o, d, INFINITY, &tb, &rb);
        assert_int_equal(hv, hb);
        if (hv) {
            assert_int_equal(rv, rb);
            assert_true(fabsf(tv - tb) <= 1e-5f * tb);
        }
    }
    /* a NaN or infinite ray hits nothing, and does not crash */
    const float o_nan[3] = {NAN, 0.5f, 0.5f}, o_ok[3] = {0.5f, 0.5f, -1.0f}, d_ok[3] = {0.0f, 0.0f, 1.0f},
                d_inf[3] = {0.0f, INFINITY, 1.0f}, d_zero[3] = {0.0f, 0.0f, 0.0f};
    assert_int_equal(lpv_probes_bvh_intersect(&b, o_nan, d_ok, INFINITY, NULL, NULL), 0);
    assert_int_equal(lpv_probes_bvh_intersect(&b, o_ok, d_inf, INFINITY, NULL, NULL), 0);
    assert_int_equal(lpv_probes_bvh_intersect(&b, o_ok, d_zero, INFINITY, NULL, NULL), 0);
    assert_int_equal(lpv_probes_bvh_intersect(&b, o_ok, d_ok, NAN, NULL, NULL), 0);
    lpv_probes_bvh_free(&b);
    mesh_free(&m);
}

/* ---- (e) empty ----------------------------------------------------------------------------- */

static void check_empty(const lpv_probes_bvh *b)
{
    assert_int_equal(b->node_count, 1);
    assert_int_equal(b->nodes[0].b, LPV_PROBES_BVH_LEAF);
    assert_int_equal(b->leaf_tri_count, 0);
    assert_int_equal(b->depth, 1);
    for (int i = 0; i < 100; i++) {
        float o[3] = {rnd() - 0.5f, rnd() - 0.5f, rnd() - 0.5f}, d[3];
        random_dir(d, i);
        float t = -1.0f;
        uint32_t tri = 12345;
        assert_int_equal(lpv_probes_bvh_intersect(b, o, d, INFINITY, &t, &tri), 0);
        assert_true(t == -1.0f && tri == 12345); /* untouched on a miss */
    }
}

static void test_empty_scene(void **state)
{
    (void)state;
    lpv_probes_bvh b;
    char err[256] = "";
    assert_int_equal(lpv_probes_bvh_build(&b, NULL, 0, NULL, 0, err, sizeof err), 0);
    check_empty(&b);
    assert_null(b.vertices);
    lpv_probes_bvh_free(&b);

    /* every triangle left out: the same empty tree, the vertices kept */
    const float pos[9] = {0, 0, 0, 1, NAN, 0, 0, 1, 0};
    const uint32_t idx[3] = {0, 1, 2};
    assert_int_equal(lpv_probes_bvh_build(&b, pos, 3, idx, 1, err, sizeof err), 0);
    check_empty(&b);
    assert_int_equal(b.skipped, 1);
    assert_int_equal(b.triangle_count, 1);
    assert_true(b.vertices[4] == 1.0f && isnan(b.vertices[5]));
    lpv_probes_bvh_free(&b);

    /* a NULL tree hits nothing */
    const float o[3] = {0, 0, 0}, d[3] = {1, 0, 0};
    assert_int_equal(lpv_probes_bvh_intersect(NULL, o, d, INFINITY, NULL, NULL), 0);
}

/* ---- leaks ------------------------------------------------------------------------------- */

/* Built and freed again and again, small and large, ok and refused: ASan's
 * leak check at exit finds anything not given back (Embree's device and
 * BVH included, which are not ours to free but ours to release). */
static void test_build_free_repeatedly(void **state)
{
    (void)state;
    char err[256];
    for (int i = 0; i < 12; i++) {
        mesh m = soup((size_t)(1 + i * 97));
        if (i % 4 == 3)
            m.idx[0] = (uint32_t)m.vertex_count;
        lpv_probes_bvh b;
        int rc = lpv_probes_bvh_build(&b, m.pos, m.vertex_count, m.idx, m.triangle_count, err, sizeof err);
        assert_int_equal(rc, i % 4 == 3 ? -1 : 0);
        if (rc == 0)
            check_structure(&b, &m, NULL);
        lpv_probes_bvh_free(&b);
        mesh_free(&m);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_soup_matches_brute_force),
        cmocka_unit_test(test_identical_triangles_lowest_id_wins),
        cmocka_unit_test(test_box_from_inside),
        cmocka_unit_test(test_index_out_of_range_is_refused),
        cmocka_unit_test(test_nonfinite_and_flat_triangles_are_never_hit),
        cmocka_unit_test(test_empty_scene),
        cmocka_unit_test(test_build_free_repeatedly),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
