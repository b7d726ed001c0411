/*
 * probes_bvh.h - the ray-tracing structure of the probes technique (issue
 * 34, DDGI-style irradiance probes): a binary bounding volume hierarchy
 * over the scene's triangles, built once on the CPU by Embree's BVH builder
 * (rtcBuildBVH) and flattened into three plain arrays that a GLSL compute
 * shader can read from shader storage buffers (std430) with no pointers:
 *
 *   nodes     lpv_probes_bvh_node[node_count], depth first, node 0 the root
 *   leaf_tris uint32[leaf_tri_count], the triangle ids each leaf names
 *   vertices  vec4[3 * triangle_count], triangle t's corners at 3t, 3t+1,
 *             3t+2 (w = 0), in the input's triangle order, so the shader
 *             needs no index buffer
 *
 * lpv_probes_bvh_intersect is the CPU traversal, written the way the shader
 * will be (iterative, a fixed stack, no allocation): it is the oracle the
 * GLSL traversal is to be compared with.
 */
#ifndef LPV_PROBES_BVH_H
#define LPV_PROBES_BVH_H

#include <stddef.h>
#include <stdint.h>

#include "lpv_shared.h"

/* One node, exactly two vec4 in std430: lpv_shared.h's struct LpvBvhNode
 * (vec4 lo, hi), whose w's are the uints a and b here, as the shaders read
 * them (probes_trace.glsl: floatBitsToUint). lo, hi: the node's own box,
 * tight around its triangles' vertices.
 *
 *   inner node: b == 0; its left child is the next node (index + 1), its
 *               right child is node a.
 *   leaf:       b & LPV_PROBES_BVH_LEAF set; its triangles are
 *               leaf_tris[a .. a + (b & LPV_PROBES_BVH_COUNT_MASK)).
 *
 * The top bit alone tells a leaf from an inner node, and no inner node
 * needs b, so it is kept 0 there (room for later use). */
typedef struct lpv_probes_bvh_node {
    float lo[3];
    uint32_t a;
    float hi[3];
    uint32_t b;
} lpv_probes_bvh_node;

_Static_assert(sizeof(lpv_probes_bvh_node) == 32, "lpv_probes_bvh_node must be two std430 vec4");
_Static_assert(offsetof(lpv_probes_bvh_node, a) == 12 && offsetof(lpv_probes_bvh_node, hi) == 16 &&
                   offsetof(lpv_probes_bvh_node, b) == 28,
               "lpv_probes_bvh_node must match std430's { vec3 lo; uint a; vec3 hi; uint b; }");

/* lpv_shared.h's struct LpvBvhNode, whose w's these name: the layout and
 * its leaf bit (LPV_PROBES_BVH_LEAF, LPV_PROBES_BVH_COUNT_MASK) are written
 * there once, for C and GLSL. */
_Static_assert(sizeof(lpv_probes_bvh_node) == sizeof(struct LpvBvhNode), "lpv_probes_bvh_node is an LpvBvhNode");

/* Most triangles a leaf holds (Embree's maxLeafSize): small, because the
 * shader tests a leaf's triangles one after another in one invocation. */
#define LPV_PROBES_BVH_LEAF_SIZE 4

/* The tree has at most LPV_PROBES_BVH_MAX_DEPTH levels (the root alone is
 * 1): Embree is given it as maxDepth, forces leaves near it, and fails the
 * build ("depth limit reached") rather than go deeper; the flattening
 * checks it again. A traversal that goes to the nearer child and pushes the
 * farther holds at most one entry per level above the node it is at, so
 * its stack of LPV_PROBES_BVH_STACK entries cannot overflow. (SAH trees of
 * 10^5 and 10^6 random triangles are 21 and 25 levels deep.) */
#define LPV_PROBES_BVH_MAX_DEPTH 48
_Static_assert(LPV_PROBES_BVH_MAX_DEPTH <= LPV_PROBES_BVH_STACK, "the traversal's stack must hold the deepest tree");

/* Most triangles: their ids, and 3 * id as a vertex index, fit a GLSL uint. */
#define LPV_PROBES_BVH_MAX_TRIANGLES (UINT32_MAX / 3u)

typedef struct lpv_probes_bvh {
    lpv_probes_bvh_node *nodes;
    size_t node_count;
    uint32_t *leaf_tris;
    size_t leaf_tri_count; /* triangle_count - skipped: each kept triangle is in exactly one leaf */
    float *vertices;       /* 4 floats a vertex, 3 vertices a triangle, every input triangle */
    size_t triangle_count;
    size_t skipped; /* triangles left out of the tree (see lpv_probes_bvh_build) */
    unsigned depth; /* levels, the root alone is 1; <= LPV_PROBES_BVH_MAX_DEPTH */
} lpv_probes_bvh;

/* Builds the hierarchy over triangle_count triangles, triangle t being the
 * vertices indices[3t], indices[3t+1], indices[3t+2] of positions (xyz per
 * vertex). Returns 0, or -1 with out zeroed and a message in err: an index
 * >= vertex_count (naming the triangle), more than
 * LPV_PROBES_BVH_MAX_TRIANGLES triangles, out of memory, or Embree's own
 * error (its message).
 *
 * A triangle with a non-finite coordinate, or with no area (its edges'
 * cross product exactly 0 in float), is left out of the tree: no leaf names
 * it, so no ray hits it, and out->skipped counts it. Its vertices are still
 * copied, as given, so vertex 3t stays triangle t's for every t.
 *
 * With no triangle left (none given, or all skipped) the tree is one empty
 * leaf: node_count 1, a = 0, b = LPV_PROBES_BVH_LEAF (count 0), box the
 * point 0; a traversal reaches it and finds nothing. (One node rather than
 * none so the node buffer is never empty: GL cannot bind an empty range.)
 *
 * Deterministic: Embree runs on one thread, so the same input gives the
 * same arrays, byte for byte. */
int lpv_probes_bvh_build(lpv_probes_bvh *out, const float *positions, size_t vertex_count, const uint32_t *indices,
                         size_t triangle_count, char *err, size_t err_size);

/* Frees the arrays and zeroes b; b zeroed (or already freed) is fine. */
void lpv_probes_bvh_free(lpv_probes_bvh *b);

/* Moller-Trumbore: 1 when the ray origin + t dir meets triangle (v0, v1, v2)
 * at 0 < t < tmax, either face, edges included (u, v >= 0, u + v <= 1);
 * *t set then. 0 when the ray is parallel to its plane (det exactly 0).
 * The traversal's triangle test, public so brute force can use the same. */
int lpv_probes_bvh_ray_triangle(const float origin[3], const float dir[3], const float v0[3], const float v1[3],
                                const float v2[3], float tmax, float *t);

/* The closest triangle along origin + t dir, 0 < t < tmax (dir need not be
 * unit; t is in its units; tmax may be INFINITY). Returns 1 and sets *t_hit,
 * *tri_hit (the input's triangle id; either may be NULL), or 0 when nothing
 * is hit, or the origin or dir has a non-finite component, or dir is 0. Two
 * triangles hit at the same t: the lower id wins if both are reached (so
 * copies of a triangle give the first, whatever leaves they are in). At an
 * edge two triangles share, a box's entry t can round past the other
 * triangle's hit; boxes are entered with a slack for that (probes_bvh.c),
 * enough for every edge tie the tests make, but not a promise. The
 * traversal tests the root's box, then at each inner node both children's
 * boxes, goes to the nearer and pushes the farther. */
int lpv_probes_bvh_intersect(const lpv_probes_bvh *b, const float origin[3], const float dir[3], float tmax,
                             float *t_hit, uint32_t *tri_hit);

#endif /* LPV_PROBES_BVH_H */
