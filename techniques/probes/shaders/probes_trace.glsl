// probes_trace.glsl - the closest triangle along a ray through the probes'
// BVH (lpv_shared.h's LpvBvhNode; techniques/probes/core/probes_bvh.h
// builds the three arrays). It follows lpv_probes_bvh_intersect step for
// step, which is its oracle (test_probes_trace_gpu.c): the root's box, then
// both children's boxes at each inner node, the nearer first and the
// farther on a fixed stack, Moller-Trumbore on a leaf's triangles, both
// faces, the lower id on a tie.

layout(std430, binding = LPV_SSBO_PROBES_NODES) readonly buffer ProbesNodes { LpvBvhNode probes_nodes[]; };
layout(std430, binding = LPV_SSBO_PROBES_LEAF_TRIS) readonly buffer ProbesLeafTris { uint probes_leaf_tris[]; };
layout(std430, binding = LPV_SSBO_PROBES_VERTS) readonly buffer ProbesVerts { vec4 probes_verts[]; };

// The slab t's are each within a relative 2 gamma(3) of the exact value
// (PBRT 3rd ed., 3.9.2): a box's interval is widened by as much each way,
// as probes_bvh.c does, so a ray along a wall's edge still enters the wall's
// flat box.
const float PROBES_BOX_FAR = 1.00000036;
const float PROBES_BOX_NEAR = 0.99999964;

// The ray's entry into node i's box within (0, limit]; still: the axes the
// ray does not move along (no 1 / 0 stands in for them).
bool probes_box(uint i, vec3 o, vec3 inv, bvec3 still, float limit, out float tnear)
{
    LpvBvhNode n = probes_nodes[i];
    float t0 = -uintBitsToFloat(0x7f800000u), t1 = uintBitsToFloat(0x7f800000u);
    tnear = 0.0;
    for (int k = 0; k < 3; ++k) {
        if (still[k]) {
            if (o[k] < n.lo[k] || o[k] > n.hi[k])
                return false;
            continue;
        }
        float a = (n.lo[k] - o[k]) * inv[k], b = (n.hi[k] - o[k]) * inv[k];
        t0 = max(t0, min(a, b) * PROBES_BOX_NEAR);
        t1 = min(t1, max(a, b) * PROBES_BOX_FAR);
    }
    if (!(t0 <= t1 && t1 > 0.0 && t0 <= limit))
        return false;
    tnear = t0;
    return true;
}

// Moller-Trumbore, both faces, edges included: lpv_probes_bvh_ray_triangle.
bool probes_triangle(vec3 o, vec3 d, uint tri, float tmax, out float t)
{
    t = 0.0;
    vec3 v0 = probes_verts[3u * tri].xyz, e1 = probes_verts[3u * tri + 1u].xyz - v0,
         e2 = probes_verts[3u * tri + 2u].xyz - v0, s = o - v0;
    vec3 p = cross(d, e2);
    float det = dot(e1, p);
    if (det == 0.0)
        return false;
    float inv = 1.0 / det, u = dot(s, p) * inv;
    if (!(u >= 0.0 && u <= 1.0))
        return false;
    vec3 q = cross(s, e1);
    float v = dot(d, q) * inv;
    if (!(v >= 0.0 && u + v <= 1.0))
        return false;
    float th = dot(e2, q) * inv;
    if (!(th > 0.0 && th < tmax))
        return false;
    t = th;
    return true;
}

// The closest hit along o + t d, 0 < t < tmax: true with t_hit and the
// input's triangle id, false when nothing is hit (or d is 0). any: stop at
// the first triangle hit (a shadow ray's question), t_hit and tri_hit then
// that one's.
bool probes_trace_ray(vec3 o, vec3 d, float tmax, bool any, out float t_hit, out uint tri_hit)
{
    t_hit = 0.0;
    tri_hit = 0u;
    if (!(tmax > 0.0) || d == vec3(0.0))
        return false;
    bvec3 still = lessThan(abs(d), vec3(1.17549435e-38));
    vec3 inv = vec3(still.x ? 0.0 : 1.0 / d.x, still.y ? 0.0 : 1.0 / d.y, still.z ? 0.0 : 1.0 / d.z);
    float best = tmax, tn;
    uint best_tri = 0u;
    bool hit = false;
    if (!probes_box(0u, o, inv, still, best, tn))
        return false;
    uint stack[LPV_PROBES_BVH_STACK];
    float stack_t[LPV_PROBES_BVH_STACK];
    int sp = 0;
    uint at = 0u;
    for (;;) {
        uint b = floatBitsToUint(probes_nodes[at].hi.w), a = floatBitsToUint(probes_nodes[at].lo.w);
        bool descend = false;
        if ((b & LPV_PROBES_BVH_LEAF) != 0u) {
            uint count = b & LPV_PROBES_BVH_COUNT_MASK;
            for (uint i = 0u; i < count; ++i) {
                uint tri = probes_leaf_tris[a + i];
                float t;
                // tmax, not best: a triangle at exactly best with a lower id still wins the tie
                if (probes_triangle(o, d, tri, tmax, t) && (!hit || t < best || (t == best && tri < best_tri))) {
                    best = t;
                    best_tri = tri;
                    hit = true;
                    if (any) {
                        t_hit = best;
                        tri_hit = best_tri;
                        return true;
                    }
                }
            }
        } else {
            uint left = at + 1u, right = a;
            float tl, tr;
            bool hl = probes_box(left, o, inv, still, best, tl), hr = probes_box(right, o, inv, still, best, tr);
            if (hl && hr) {
                bool left_first = tl <= tr;
                if (sp < LPV_PROBES_BVH_STACK) {
                    stack[sp] = left_first ? right : left;
                    stack_t[sp] = left_first ? tr : tl;
                    ++sp;
                }
                at = left_first ? left : right;
                descend = true;
            } else if (hl || hr) {
                at = hl ? left : right;
                descend = true;
            }
        }
        if (descend)
            continue;
        // the next node on the stack still nearer than the closest hit
        bool found = false;
        while (sp > 0) {
            --sp;
            if (stack_t[sp] <= best) {
                found = true;
                break;
            }
        }
        if (!found)
            break;
        at = stack[sp];
    }
    t_hit = best;
    tri_hit = best_tri;
    return hit;
}

bool probes_closest_hit(vec3 o, vec3 d, float tmax, out float t_hit, out uint tri_hit)
{
    return probes_trace_ray(o, d, tmax, false, t_hit, tri_hit);
}

// Whether anything lies on o + t d, 0 < t < tmax.
bool probes_any_hit(vec3 o, vec3 d, float tmax)
{
    float t;
    uint tri;
    return probes_trace_ray(o, d, tmax, true, t, tri);
}
