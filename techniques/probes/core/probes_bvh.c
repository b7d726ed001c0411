/*
 * probes_bvh.c - the probes' BVH: Embree builds a binary tree, this file
 * flattens it into the std430 node array and traverses that array the way
 * the shader will (see probes_bvh.h).
 */
#include "probes_bvh.h"

#include <float.h>
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include <embree3/rtcore.h>
#include <embree3/rtcore_builder.h>

#include "error.h"

/* ---- Embree's tree ------------------------------------------------------------ */

/* One node of the tree Embree builds through the callbacks below, in memory
 * from rtcThreadLocalAlloc (freed with the RTCBVH). One type for both kinds,
 * so the flattening reads any node through one struct: a leaf has no
 * children and its ids in tri[]; an inner node has two children and their
 * boxes (Embree hands a node its children's boxes, never its own). */
typedef struct build_node {
    struct build_node *child[2]; /* both NULL: a leaf */
    float box[2][6];             /* the children's: lo xyz, hi xyz */
    uint32_t count;              /* leaf: how many ids in tri */
    uint32_t tri[];
} build_node;

typedef struct build_state {
    /* set when a callback could not do its part (no memory, or a node shape
     * this file does not expect); the callbacks may run on Embree's threads,
     * hence atomic, though the device is asked for one */
    atomic_int failed;
    char embree_msg[256]; /* Embree's first error message, from the device's error callback */
} build_state;

static void *create_node(RTCThreadLocalAllocator alloc, unsigned int child_count, void *user)
{
    build_state *st = user;
    /* maxBranchingFactor is 2, so every inner node has exactly 2 children;
     * anything else would not fit the flat layout */
    build_node *n = child_count == 2 ? rtcThreadLocalAlloc(alloc, sizeof *n, 16) : NULL;
    if (!n) {
        atomic_store(&st->failed, 1);
        return NULL;
    }
    n->child[0] = n->child[1] = NULL;
    n->count = 0;
    return n;
}

static void set_node_children(void *node, void **children, unsigned int child_count, void *user)
{
    build_node *n = node;
    if (!n || child_count != 2 || !children[0] || !children[1]) {
        atomic_store(&((build_state *)user)->failed, 1);
        return;
    }
    n->child[0] = children[0];
    n->child[1] = children[1];
}

static void set_node_bounds(void *node, const struct RTCBounds **bounds, unsigned int child_count, void *user)
{
    build_node *n = node;
    if (!n || child_count != 2) {
        atomic_store(&((build_state *)user)->failed, 1);
        return;
    }
    for (int c = 0; c < 2; c++) {
        const struct RTCBounds *b = bounds[c];
        const float box[6] = {b->lower_x, b->lower_y, b->lower_z, b->upper_x, b->upper_y, b->upper_z};
        memcpy(n->box[c], box, sizeof box);
    }
}

static void *create_leaf(RTCThreadLocalAllocator alloc, const struct RTCBuildPrimitive *prims, size_t count,
                         void *user)
{
    build_state *st = user;
    build_node *n =
        count <= LPV_PROBES_BVH_LEAF_SIZE ? rtcThreadLocalAlloc(alloc, sizeof *n + count * sizeof(uint32_t), 16) : NULL;
    if (!n) {
        atomic_store(&st->failed, 1);
        return NULL;
    }
    n->child[0] = n->child[1] = NULL;
    n->count = (uint32_t)count;
    /* primID is the input's triangle id: Embree reorders the primitive
     * array while it partitions, so the position in it means nothing */
    for (size_t i = 0; i < count; i++)
        n->tri[i] = prims[i].primID;
    return n;
}

static void on_embree_error(void *user, enum RTCError code, const char *str)
{
    build_state *st = user;
    (void)code;
    if (st->embree_msg[0] == '\0' && str) {
        strncpy(st->embree_msg, str, sizeof st->embree_msg - 1);
        st->embree_msg[sizeof st->embree_msg - 1] = '\0';
    }
}

static const char *embree_error_name(enum RTCError e)
{
    switch (e) {
    case RTC_ERROR_NONE: return "no error";
    case RTC_ERROR_UNKNOWN: return "unknown error";
    case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY: return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
    case RTC_ERROR_CANCELLED: return "cancelled";
    }
    return "error";
}

/* ---- Flattening ------------------------------------------------------------------ */

typedef struct flat {
    lpv_probes_bvh *out;
    size_t nodes, tris; /* filled so far */
} flat;

/* Counts the nodes and leaf entries under n (n at level `level`, the root
 * being 1) and the deepest level. 0, or -1 for a tree that is malformed or
 * deeper than LPV_PROBES_BVH_MAX_DEPTH (Embree should have refused it; the
 * traversal's stack depends on it); the check comes before the recursion,
 * so the recursion is never deeper than that either. */
static int count_tree(const build_node *n, unsigned level, size_t *nodes, size_t *tris, unsigned *depth)
{
    if (!n || level > LPV_PROBES_BVH_MAX_DEPTH)
        return -1;
    if (level > *depth)
        *depth = level;
    ++*nodes;
    if (!n->child[0] && !n->child[1]) {
        *tris += n->count;
        return 0;
    }
    if (!n->child[0] || !n->child[1])
        return -1;
    if (count_tree(n->child[0], level + 1, nodes, tris, depth) != 0)
        return -1;
    return count_tree(n->child[1], level + 1, nodes, tris, depth);
}

/* Writes n, whose box is box (given by its parent, or the scene's for the
 * root), and then its subtree depth first: the left child right after n,
 * so only the right child's index need be stored. */
static void emit(flat *f, const build_node *n, const float box[6])
{
    lpv_probes_bvh_node *d = &f->out->nodes[f->nodes++];
    memcpy(d->lo, box, 3 * sizeof(float));
    memcpy(d->hi, box + 3, 3 * sizeof(float));
    if (!n->child[0]) {
        d->a = (uint32_t)f->tris;
        d->b = LPV_PROBES_BVH_LEAF | n->count;
        memcpy(f->out->leaf_tris + f->tris, n->tri, n->count * sizeof(uint32_t));
        f->tris += n->count;
        return;
    }
    d->b = 0;
    emit(f, n->child[0], n->box[0]);
    d->a = (uint32_t)f->nodes; /* the right child: next after the left subtree */
    emit(f, n->child[1], n->box[1]);
}

/* ---- Build ------------------------------------------------------------------------- */

static int finite_tri(const float *p[3])
{
    for (int k = 0; k < 3; k++)
        if (!isfinite(p[k][0]) || !isfinite(p[k][1]) || !isfinite(p[k][2]))
            return 0;
    return 1;
}

/* 1 when the edges' cross product is exactly 0 in float: the corners
 * coincide or lie on one line, so the triangle has no area to be hit
 * (Moller-Trumbore's determinant is then 0 or rounding noise; leaving it out
 * of the tree makes "never hit" certain rather than likely). */
static int zero_area(const float *p[3])
{
    float e1[3], e2[3];
    for (int k = 0; k < 3; k++) {
        e1[k] = p[1][k] - p[0][k];
        e2[k] = p[2][k] - p[0][k];
    }
    return e1[1] * e2[2] - e1[2] * e2[1] == 0.0f && e1[2] * e2[0] - e1[0] * e2[2] == 0.0f &&
           e1[0] * e2[1] - e1[1] * e2[0] == 0.0f;
}

void lpv_probes_bvh_free(lpv_probes_bvh *b)
{
    if (!b)
        return;
    free(b->nodes);
    free(b->leaf_tris);
    free(b->vertices);
    memset(b, 0, sizeof *b);
}

/* The tree of no triangles: one empty leaf (see probes_bvh.h). */
static int make_empty(lpv_probes_bvh *out, char *err, size_t err_size)
{
    out->nodes = calloc(1, sizeof *out->nodes);
    if (!out->nodes)
        return lpv_error(err, err_size, "probes: BVH: out of memory");
    out->node_count = 1;
    out->nodes[0].a = 0;
    out->nodes[0].b = LPV_PROBES_BVH_LEAF;
    out->depth = 1;
    return 0;
}

int lpv_probes_bvh_build(lpv_probes_bvh *out, const float *positions, size_t vertex_count, const uint32_t *indices,
                         size_t triangle_count, char *err, size_t err_size)
{
    if (!out)
        return lpv_error(err, err_size, "probes: BVH: no output");
    memset(out, 0, sizeof *out);
    if (triangle_count > LPV_PROBES_BVH_MAX_TRIANGLES)
        return lpv_error(err, err_size, "probes: BVH: %zu triangles, at most %u", triangle_count,
                         (unsigned)LPV_PROBES_BVH_MAX_TRIANGLES);
    if (triangle_count > 0 && (!positions || !indices))
        return lpv_error(err, err_size, "probes: BVH: %zu triangles but no %s", triangle_count,
                         !positions ? "positions" : "indices");
    /* every index checked before anything is allocated, so a bad mesh costs
     * no Embree device */
    for (size_t t = 0; t < triangle_count; t++)
        for (int k = 0; k < 3; k++)
            if (indices[3 * t + (size_t)k] >= vertex_count)
                return lpv_error(err, err_size,
                                 "probes: BVH: triangle %zu: vertex index %u out of range (%zu vertices)", t,
                                 indices[3 * t + (size_t)k], vertex_count);

    out->triangle_count = triangle_count;
    if (triangle_count > 0) {
        out->vertices = malloc(triangle_count * 12 * sizeof(float));
        if (!out->vertices) {
            lpv_probes_bvh_free(out);
            return lpv_error(err, err_size, "probes: BVH: out of memory for %zu triangles", triangle_count);
        }
    }

    /* RTCBuildPrimitive is declared RTC_ALIGN(32) and Embree reads the
     * array with aligned vector loads: malloc's 16 bytes are not enough.
     * Capacity = count: no spatial splits (see below), so no spare room. */
    struct RTCBuildPrimitive *prims = NULL;
    if (triangle_count > 0) {
        prims = aligned_alloc(32, triangle_count * sizeof *prims);
        if (!prims) {
            lpv_probes_bvh_free(out);
            return lpv_error(err, err_size, "probes: BVH: out of memory for %zu triangles", triangle_count);
        }
    }
    size_t kept = 0;
    float scene[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    for (size_t t = 0; t < triangle_count; t++) {
        const float *p[3];
        for (int k = 0; k < 3; k++) {
            p[k] = positions + 3 * (size_t)indices[3 * t + (size_t)k];
            float *v = out->vertices + 12 * t + 4 * (size_t)k;
            v[0] = p[k][0];
            v[1] = p[k][1];
            v[2] = p[k][2];
            v[3] = 0.0f;
        }
        /* a non-finite corner would give a NaN or infinite box, which
         * poisons every box above it (and Embree's binning); one with no
         * area has nothing to hit */
        if (!finite_tri(p) || zero_area(p)) {
            out->skipped++;
            continue;
        }
        float lo[3], hi[3];
        for (int a = 0; a < 3; a++) {
            lo[a] = fminf(p[0][a], fminf(p[1][a], p[2][a]));
            hi[a] = fmaxf(p[0][a], fmaxf(p[1][a], p[2][a]));
            scene[a] = fminf(scene[a], lo[a]);
            scene[3 + a] = fmaxf(scene[3 + a], hi[a]);
        }
        struct RTCBuildPrimitive *bp = &prims[kept++];
        bp->lower_x = lo[0];
        bp->lower_y = lo[1];
        bp->lower_z = lo[2];
        bp->upper_x = hi[0];
        bp->upper_y = hi[1];
        bp->upper_z = hi[2];
        bp->geomID = 0;
        bp->primID = (unsigned)t;
    }
    if (kept == 0) {
        free(prims);
        if (make_empty(out, err, err_size) != 0) {
            lpv_probes_bvh_free(out);
            return -1;
        }
        return 0;
    }

    /* One thread: the same input then gives the same tree (Embree's
     * parallel partitioning may order primitives differently run to run),
     * and the daemon's own threads are not joined by Embree's pool. */
    build_state st = {.failed = 0};
    st.embree_msg[0] = '\0';
    RTCDevice device = rtcNewDevice("threads=1");
    if (!device) {
        free(prims);
        lpv_probes_bvh_free(out);
        return lpv_error(err, err_size, "probes: BVH: Embree: rtcNewDevice failed (%s)",
                         embree_error_name(rtcGetDeviceError(NULL)));
    }
    rtcSetDeviceErrorFunction(device, on_embree_error, &st);
    RTCBVH bvh = rtcNewBVH(device);

    struct RTCBuildArguments args = rtcDefaultBuildArguments();
    /* MEDIUM, Embree's binned SAH builder. HIGH adds spatial splits only
     * given a splitPrimitive callback and primitiveArrayCapacity above the
     * count (without them HIGH runs this same builder); splits would put a
     * triangle in several leaves, so leaf_tris would be longer than the
     * triangle count by an amount known only after the build, and "each
     * triangle in exactly one leaf", which the tests check, would no longer
     * hold. Worth measuring when the shader exists: splits pay off for long
     * thin triangles. */
    args.buildQuality = RTC_BUILD_QUALITY_MEDIUM;
    args.maxBranchingFactor = 2;
    args.maxDepth = LPV_PROBES_BVH_MAX_DEPTH;
    args.minLeafSize = 1;
    args.maxLeafSize = LPV_PROBES_BVH_LEAF_SIZE;
    args.bvh = bvh;
    args.primitives = prims;
    args.primitiveCount = kept;
    args.primitiveArrayCapacity = kept;
    args.createNode = create_node;
    args.setNodeChildren = set_node_children;
    args.setNodeBounds = set_node_bounds;
    args.createLeaf = create_leaf;
    args.splitPrimitive = NULL;
    args.buildProgress = NULL;
    args.userPtr = &st;

    int rc = 0;
    const build_node *root = bvh ? rtcBuildBVH(&args) : NULL;
    enum RTCError e = rtcGetDeviceError(device);
    size_t node_count = 0, leaf_tris = 0;
    unsigned depth = 0;
    if (!root || e != RTC_ERROR_NONE || atomic_load(&st.failed)) {
        if (st.embree_msg[0])
            rc = lpv_error(err, err_size, "probes: BVH: Embree: %s (%s)", st.embree_msg, embree_error_name(e));
        else if (e != RTC_ERROR_NONE)
            rc = lpv_error(err, err_size, "probes: BVH: Embree: %s", embree_error_name(e));
        else
            rc = lpv_error(err, err_size, "probes: BVH: building the tree failed (out of memory in a callback)");
    } else if (count_tree(root, 1, &node_count, &leaf_tris, &depth) != 0 || leaf_tris != kept) {
        rc = lpv_error(err, err_size, "probes: BVH: Embree's tree is malformed or deeper than %d levels",
                       LPV_PROBES_BVH_MAX_DEPTH);
    } else {
        out->nodes = malloc(node_count * sizeof *out->nodes);
        out->leaf_tris = malloc(leaf_tris * sizeof *out->leaf_tris);
        if (!out->nodes || !out->leaf_tris) {
            rc = lpv_error(err, err_size, "probes: BVH: out of memory for %zu nodes", node_count);
        } else {
            flat f = {.out = out, .nodes = 0, .tris = 0};
            emit(&f, root, scene);
            out->node_count = node_count;
            out->leaf_tri_count = leaf_tris;
            out->depth = depth;
        }
    }
    /* the tree lives in the BVH's allocator: flattened (or failed), it goes */
    if (bvh)
        rtcReleaseBVH(bvh);
    rtcReleaseDevice(device);
    free(prims);
    if (rc != 0)
        lpv_probes_bvh_free(out);
    return rc;
}

/* ---- Traversal --------------------------------------------------------------------- */

int lpv_probes_bvh_ray_triangle(const float o[3], const float d[3], const float v0[3], const float v1[3],
                                const float v2[3], float tmax, float *t)
{
    float e1[3], e2[3], s[3];
    for (int k = 0; k < 3; k++) {
        e1[k] = v1[k] - v0[k];
        e2[k] = v2[k] - v0[k];
        s[k] = o[k] - v0[k];
    }
    const float p[3] = {d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2], d[0] * e2[1] - d[1] * e2[0]};
    const float det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
    /* exactly 0 only: an epsilon would depend on the scene's units. A
     * near-zero one (a ray grazing the plane) can make inv, u, v or t
     * infinite or NaN; the checks below are written to fail on NaN. */
    if (det == 0.0f)
        return 0;
    const float inv = 1.0f / det;
    const float u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) * inv;
    if (!(u >= 0.0f && u <= 1.0f))
        return 0;
    const float q[3] = {s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2], s[0] * e1[1] - s[1] * e1[0]};
    const float v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) * inv;
    if (!(v >= 0.0f && u + v <= 1.0f))
        return 0;
    const float th = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) * inv;
    if (!(th > 0.0f && th < tmax))
        return 0;
    *t = th;
    return 1;
}

/* A slab's t's are computed in float, each within a relative 2 gamma(3)
 * of the exact value (Pharr, Jakob, Humphreys, PBRT 3rd ed., 3.9.2), and
 * the triangle test's t is off by as much again. So the far end of a box's
 * interval is stretched by 1 + 2 gamma(3) and the near end pulled in by as
 * much: without the first, a ray at a wall's edge (an axis-aligned wall
 * has a flat box) misses the box by one rounding while the triangle test
 * hits; without the second, a box entered at t = 1.0 was skipped for a hit
 * at 0.99999994 while its own triangle was hit at 0.99999994 too. */
#define BOX_FAR_SCALE 1.00000036f
#define BOX_NEAR_SCALE 0.99999964f

/* The ray's entry into box n when it meets it within (0, limit] (1, *tnear
 * set; tnear < 0 when the origin is inside), 0 otherwise. inv[k] = 1 /
 * dir[k], finite; still[k] set where dir[k] is 0 (or subnormal): along that
 * axis the ray stays where it starts, inside the slab or never in it. No
 * 1 / 0 stands in for it: (lo - o) * inf is NaN for an origin in the
 * slab's plane, and a tiny stand-in direction has the ray leave the slab
 * at t = 0 there, so a ray along a floor would miss the wall it meets. */
static int box_hit(const lpv_probes_bvh_node *n, const float o[3], const float inv[3], const int still[3], float limit,
                   float *tnear)
{
    float t0 = -INFINITY, t1 = INFINITY;
    for (int k = 0; k < 3; k++) {
        if (still[k]) {
            if (o[k] < n->lo[k] || o[k] > n->hi[k])
                return 0;
            continue;
        }
        float a = (n->lo[k] - o[k]) * inv[k], b = (n->hi[k] - o[k]) * inv[k];
        float lo = (a < b ? a : b) * BOX_NEAR_SCALE, hi = (a < b ? b : a) * BOX_FAR_SCALE;
        t0 = lo > t0 ? lo : t0;
        t1 = hi < t1 ? hi : t1;
    }
    if (!(t0 <= t1 && t1 > 0.0f && t0 <= limit))
        return 0;
    *tnear = t0;
    return 1;
}

int lpv_probes_bvh_intersect(const lpv_probes_bvh *b, const float origin[3], const float dir[3], float tmax,
                             float *t_hit, uint32_t *tri_hit)
{
    if (!b || !b->nodes || b->node_count == 0 || !(tmax > 0.0f))
        return 0;
    for (int k = 0; k < 3; k++)
        if (!isfinite(origin[k]) || !isfinite(dir[k]))
            return 0;
    if (dir[0] == 0.0f && dir[1] == 0.0f && dir[2] == 0.0f)
        return 0;
    /* below FLT_MIN 1 / dir could be infinite; such a component moves the
     * ray by less than 1e-38 of its length: counted as none (a GPU flushes
     * subnormals to 0 anyway) */
    float inv[3];
    int still[3];
    for (int k = 0; k < 3; k++) {
        still[k] = fabsf(dir[k]) < FLT_MIN;
        inv[k] = still[k] ? 0.0f : 1.0f / dir[k];
    }

    const lpv_probes_bvh_node *nodes = b->nodes;
    float best = tmax, tn;
    uint32_t best_tri = 0;
    int hit = 0;
    if (!box_hit(&nodes[0], origin, inv, still, best, &tn))
        return 0;

    /* each entry: a node whose box the ray meets, and where it enters it, so
     * a node found farther than a hit made since it was pushed is skipped */
    uint32_t stack[LPV_PROBES_BVH_STACK];
    float stack_t[LPV_PROBES_BVH_STACK];
    unsigned sp = 0;
    uint32_t at = 0;
    for (;;) {
        const lpv_probes_bvh_node *n = &nodes[at];
        if (n->b & LPV_PROBES_BVH_LEAF) {
            const uint32_t first = n->a, count = n->b & LPV_PROBES_BVH_COUNT_MASK;
            for (uint32_t i = 0; i < count; i++) {
                const uint32_t tri = b->leaf_tris[first + i];
                const float *v = b->vertices + 12 * (size_t)tri;
                float t;
                /* tmax, not best, as the limit: a triangle at exactly best
                 * with a lower id must still win the tie */
                if (lpv_probes_bvh_ray_triangle(origin, dir, v, v + 4, v + 8, tmax, &t) &&
                    (!hit || t < best || (t == best && tri < best_tri))) {
                    best = t;
                    best_tri = tri;
                    hit = 1;
                }
            }
        } else {
            const uint32_t left = at + 1, right = n->a;
            float tl, tr;
            const int hl = box_hit(&nodes[left], origin, inv, still, best, &tl);
            const int hr = box_hit(&nodes[right], origin, inv, still, best, &tr);
            if (hl && hr) {
                /* nearer first: its hits shrink best before the farther box
                 * is looked at, which then is often skipped */
                const int left_first = tl <= tr;
                /* cannot overflow for a tree from lpv_probes_bvh_build (at
                 * most LPV_PROBES_BVH_MAX_DEPTH levels, and a path of that
                 * many pushes at most one less); the guard keeps a hand-made
                 * array from writing past the stack, dropping the farther
                 * subtree */
                if (sp < LPV_PROBES_BVH_STACK) {
                    stack[sp] = left_first ? right : left;
                    stack_t[sp] = left_first ? tr : tl;
                    sp++;
                }
                at = left_first ? left : right;
                continue;
            }
            if (hl || hr) {
                at = hl ? left : right;
                continue;
            }
        }
        /* pop the next node still nearer than the closest hit */
        for (;;) {
            if (sp == 0)
                goto done;
            sp--;
            if (stack_t[sp] <= best)
                break;
        }
        at = stack[sp];
    }
done:
    if (hit) {
        if (t_hit)
            *t_hit = best;
        if (tri_hit)
            *tri_hit = best_tri;
    }
    return hit;
}
