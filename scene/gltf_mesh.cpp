/*
 * gltf_mesh.cpp - the Builder's primitives (gltf_internal.hpp): a triangle,
 * strip or fan primitive, its attributes from the accessors or from
 * KHR_draco_mesh_compression (gltf_compressed.hpp), into world-space vertices
 * and one draw; a point or line primitive into one wire draw. Normals move with the normal matrix, a mirroring transform
 * flips the winding, and a primitive without normals gets flat ones from its
 * world winding (its vertices un-shared).
 */
#include "gltf_internal.hpp"

#include <algorithm>
#include "gltf_compressed.hpp"

#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace lpv_gltf {

void Builder::add_primitive(const tinygltf::Primitive &p, int mesh, int prim, const Mat4 &world, const Deform &deform)
{
    const int mode = p.mode;
    if (mode < TINYGLTF_MODE_POINTS || mode > TINYGLTF_MODE_TRIANGLE_FAN) {
        ctx_.warn(strf("mesh %d primitive %d: unknown mode %d skipped", mesh, prim, mode));
        return;
    }
    const bool wire = mode == TINYGLTF_MODE_POINTS || mode == TINYGLTF_MODE_LINE ||
                      mode == TINYGLTF_MODE_LINE_LOOP || mode == TINYGLTF_MODE_LINE_STRIP;
    auto pos_it = p.attributes.find("POSITION");
    if (pos_it == p.attributes.end()) {
        ctx_.warn(strf("mesh %d primitive %d has no POSITION; skipped", mesh, prim));
        return;
    }
    /* KHR_draco_mesh_compression: the attributes and indices come from the
     * Draco bitstream instead of the accessors (which hold no data). */
    DracoMesh draco;
    bool is_draco = false;
    auto dext = p.extensions.find("KHR_draco_mesh_compression");
    if (dext != p.extensions.end()) {
        const tinygltf::Value &d = dext->second;
        const tinygltf::Value none;
        const tinygltf::Value &bvv = d.IsObject() && d.Has("bufferView") ? d.Get("bufferView") : none;
        const tinygltf::Value &attrs = d.IsObject() && d.Has("attributes") ? d.Get("attributes") : none;
        if (!bvv.IsNumber() || !attrs.IsObject())
            fail("mesh %d primitive %d: KHR_draco_mesh_compression needs a bufferView and attributes", mesh, prim);
        std::map<std::string, int> ids, comps = {{"POSITION", 3}, {"NORMAL", 3}, {"TEXCOORD_0", 2},
                                                 {"TEXCOORD_1", 2}, {"TANGENT", 4}, {"COLOR_0", 4}};
        for (const std::string &k : attrs.Keys()) {
            const tinygltf::Value &id = attrs.Get(k);
            double v = id.IsNumber() ? id.GetNumberAsDouble() : -1.0;
            if (!(v >= 0.0 && v <= double(INT_MAX)) || v != std::floor(v))
                fail("mesh %d primitive %d: KHR_draco_mesh_compression.attributes.%s must be an integer >= 0", mesh,
                     prim, show(k).c_str());
            ids[k] = int(v);
        }
        if (!ids.count("POSITION"))
            fail("mesh %d primitive %d: KHR_draco_mesh_compression has no POSITION attribute", mesh, prim);
        double bvd = bvv.GetNumberAsDouble();
        if (!(bvd >= 0.0 && bvd < double(m_.bufferViews.size())) || bvd != std::floor(bvd))
            fail("mesh %d primitive %d: KHR_draco_mesh_compression bufferView %g does not exist (out of range)", mesh,
                 prim, bvd);
        View dv = view(int(bvd), "KHR_draco_mesh_compression of mesh", mesh);
        std::string e = draco_decode(dv.data, dv.length, ids, comps, size_t(kMaxAccessorCount), &draco);
        if (!e.empty())
            fail("mesh %d primitive %d: %s", mesh, prim, e.c_str());
        is_draco = true;
    }
    /* One vertex attribute: from the Draco data, else its accessor. */
    char what[96];
    auto attribute = [&](const char *name, int ncomp, std::vector<float> &out) -> bool {
        auto it = p.attributes.find(name);
        if (is_draco) {
            auto d = draco.attributes.find(name);
            if (d != draco.attributes.end()) {
                out = d->second;
                return true;
            }
        }
        if (it == p.attributes.end())
            return false;
        snprintf(what, sizeof what, "mesh %d primitive %d %s", mesh, prim, name);
        if (is_draco && m_.accessors.size() > size_t(it->second) && m_.accessors[size_t(it->second)].bufferView < 0 &&
            !m_.accessors[size_t(it->second)].sparse.isSparse)
            return false; /* listed, but neither compressed nor stored: no data */
        read_accessor(it->second, ncomp, what, out);
        return true;
    };
    std::vector<float> pos;
    attribute("POSITION", 3, pos);
    const size_t nv = pos.size() / 3;
    for (size_t i = 0; i < pos.size(); i++)
        if (!std::isfinite(pos[i]))
            fail("mesh %d primitive %d: POSITION of vertex %zu is not finite (NaN or Inf)", mesh, prim, i / 3);

    std::vector<float> nrm, uv, uv1, tan;
    struct {
        const char *name;
        int ncomp;
        std::vector<float> *out;
    } extra[] = {{"NORMAL", 3, &nrm}, {"TEXCOORD_0", 2, &uv}, {"TEXCOORD_1", 2, &uv1}, {"TANGENT", 4, &tan}};
    for (const auto &a : extra)
        if (attribute(a.name, a.ncomp, *a.out) && a.out->size() / size_t(a.ncomp) != nv)
            fail("mesh %d primitive %d: %s has %zu elements but POSITION has %zu", mesh, prim, a.name,
                 a.out->size() / size_t(a.ncomp), nv);

    /* Morph targets (glTF 2.0): each target's POSITION, NORMAL and TANGENT
     * displacements, weighted by the instance's weights, added to the base
     * before any transform (a normal or tangent displacement is renormalized
     * after). Draco-compressed primitives carry their targets in accessors
     * too. */
    for (size_t k = 0; k < p.targets.size() && k < deform.weights.size(); k++) {
        const double wk = deform.weights[k];
        if (wk == 0.0)
            continue;
        struct {
            const char *name;
            std::vector<float> *base;
            int stride;
        } parts[] = {{"POSITION", &pos, 3}, {"NORMAL", &nrm, 3}, {"TANGENT", &tan, 4}};
        for (const auto &part : parts) {
            auto it = p.targets[k].find(part.name);
            if (it == p.targets[k].end() || part.base->empty())
                continue;
            std::vector<float> delta;
            snprintf(what, sizeof what, "mesh %d primitive %d target %zu %s", mesh, prim, k, part.name);
            read_accessor(it->second, 3, what, delta);
            if (delta.size() / 3 != nv)
                fail("mesh %d primitive %d: morph target %zu %s has %zu elements but POSITION has %zu", mesh, prim,
                     k, part.name, delta.size() / 3, nv);
            for (size_t v = 0; v < nv; v++)
                for (int c = 0; c < 3; c++)
                    (*part.base)[v * size_t(part.stride) + size_t(c)] += float(wk * delta[v * 3 + size_t(c)]);
        }
    }
    for (size_t i = 0; i < pos.size(); i++)
        if (!std::isfinite(pos[i]))
            fail("mesh %d primitive %d: morphed POSITION of vertex %zu is not finite", mesh, prim, i / 3);

    /* Skinning (glTF 2.0): each vertex moves with the weighted sum of its
     * joints' matrices (JOINTS_n / WEIGHTS_n, every set the file has; the
     * weights normalized to sum to 1), in place of the node's transform. */
    std::vector<Mat4> skin_m;
    if (!deform.joints.empty()) {
        std::vector<double> acc(nv * 16, 0.0), wsum(nv, 0.0);
        int sets = 0;
        for (int set = 0;; set++) {
            const std::string jn = "JOINTS_" + std::to_string(set), wn = "WEIGHTS_" + std::to_string(set);
            auto jit = p.attributes.find(jn), wit = p.attributes.find(wn);
            if (jit == p.attributes.end() || wit == p.attributes.end())
                break;
            std::vector<float> jv, wv;
            snprintf(what, sizeof what, "mesh %d primitive %d %s", mesh, prim, jn.c_str());
            read_accessor(jit->second, 4, what, jv);
            snprintf(what, sizeof what, "mesh %d primitive %d %s", mesh, prim, wn.c_str());
            read_accessor(wit->second, 4, what, wv);
            if (jv.size() / 4 != nv || wv.size() / 4 != nv)
                fail("mesh %d primitive %d: %s or %s does not have one element per vertex (%zu)", mesh, prim,
                     jn.c_str(), wn.c_str(), nv);
            for (size_t v = 0; v < nv; v++)
                for (int c = 0; c < 4; c++) {
                    const double w = wv[v * 4 + size_t(c)];
                    if (!(w > 0.0))
                        continue;
                    const double j = jv[v * 4 + size_t(c)];
                    if (!(j >= 0.0 && j < double(deform.joints.size())) || j != std::floor(j))
                        fail("mesh %d primitive %d: %s of vertex %zu names joint %g; the skin has %zu", mesh, prim,
                             jn.c_str(), v, j, deform.joints.size());
                    const Mat4 &m = deform.joints[size_t(j)];
                    for (int e = 0; e < 16; e++)
                        acc[v * 16 + size_t(e)] += w * m.m[e];
                    wsum[v] += w;
                }
            sets++;
        }
        if (!sets) /* (invalid glTF) drawn where its node stands */
            ctx_.warn(strf("mesh %d: skinned, but without JOINTS_0 and WEIGHTS_0; drawn unskinned at its node",
                           mesh));
        else
            skin_m.resize(nv);
        for (size_t v = 0; v < skin_m.size(); v++) {
            if (!(wsum[v] > 0.0))
                fail("mesh %d primitive %d: vertex %zu has no joint weight (its WEIGHTS sum to 0)", mesh, prim, v);
            for (int e = 0; e < 16; e++)
                skin_m[v].m[e] = acc[v * 16 + size_t(e)] / wsum[v];
        }
    }

    /* COLOR_0: VEC3 or VEC4, float or normalized unsigned byte/short
     * (read_accessor normalizes); linear RGB(A) multiplying the base colour */
    std::vector<float> col;
    int col_comps = 0;
    {
        auto it = p.attributes.find("COLOR_0");
        const bool in_draco = is_draco && draco.attributes.count("COLOR_0");
        if (in_draco) {
            col = draco.attributes["COLOR_0"]; /* RGBA (gltf_compressed.cpp) */
            col_comps = 4;
        } else if (it != p.attributes.end() && it->second >= 0 && size_t(it->second) < m_.accessors.size()) {
            col_comps = m_.accessors[size_t(it->second)].type == TINYGLTF_TYPE_VEC4 ? 4 : 3;
            snprintf(what, sizeof what, "mesh %d primitive %d COLOR_0", mesh, prim);
            read_accessor(it->second, col_comps, what, col);
        }
        if (!col.empty() && col.size() != nv * size_t(col_comps))
            fail("mesh %d primitive %d: COLOR_0 has %zu elements but POSITION has %zu", mesh, prim,
                 col.size() / size_t(col_comps ? col_comps : 1), nv);
    }

    std::vector<uint32_t> idx;
    if (is_draco) {
        idx = draco.indices;
    } else if (p.indices >= 0) {
        read_indices(p.indices, idx);
    } else {
        idx.resize(nv);
        for (size_t i = 0; i < nv; i++)
            idx[i] = uint32_t(i);
    }
    for (size_t i = 0; i < idx.size(); i++)
        if (idx[i] >= nv)
            fail("mesh %d primitive %d: index %u at position %zu is out of range (vertex count %zu)", mesh, prim,
                 idx[i], i, nv);

    /* Points and lines: a point per index, or a segment per pair (strips
     * and loops unrolled), drawn by the camera only (lpv_scene.wire_draws) */
    const size_t ni = idx.size();
    std::vector<uint32_t> seg;
    if (mode == TINYGLTF_MODE_POINTS) {
        seg = idx;
    } else if (mode == TINYGLTF_MODE_LINE) {
        seg.assign(idx.begin(), idx.begin() + ptrdiff_t(ni - ni % 2));
    } else if (wire && ni >= 2) {
        for (size_t i = 0; i + 1 < ni; i++)
            seg.insert(seg.end(), {idx[i], idx[i + 1]});
        if (mode == TINYGLTF_MODE_LINE_LOOP && ni > 2)
            seg.insert(seg.end(), {idx[ni - 1], idx[0]});
    }
    /* Triangle list in glTF's vertex order per mode. */
    std::vector<uint32_t> tri;
    if (wire) {
        /* none */
    } else if (mode == TINYGLTF_MODE_TRIANGLES) {
        tri.assign(idx.begin(), idx.begin() + ptrdiff_t(ni - ni % 3));
    } else if (ni >= 3) {
        tri.reserve((ni - 2) * 3);
        for (size_t i = 0; i + 2 < ni; i++) {
            if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
                size_t b = i + 1 + (i % 2), c = i + 2 - (i % 2);
                tri.insert(tri.end(), {idx[i], idx[b], idx[c]});
            } else {
                tri.insert(tri.end(), {idx[i + 1], idx[i + 2], idx[0]});
            }
        }
    }
    const size_t ntri = tri.size() / 3;
    if (ntri == 0 && seg.empty())
        return;
    if (uint64_t(indices.size()) / 3 + ntri > kMaxTriangles)
        fail("more than %llu triangles (absurd size)", (unsigned long long)kMaxTriangles);

    int material;
    if (p.material >= 0) {
        if (size_t(p.material) >= m_.materials.size())
            fail("mesh %d primitive %d: material %d does not exist (out of range)", mesh, prim, p.material);
        material = p.material;
    } else {
        material = default_material();
    }

    if (uv1.empty() && size_t(material) < material_uv1_.size() && material_uv1_[size_t(material)])
        ctx_.warn(strf("material %d reads TEXCOORD_1, which mesh %d primitive %d lacks; (0, 0) is used there",
                       material, mesh, prim));

    /* the transform of vertex v: the node's, or its skinning matrix */
    auto mat_of = [&](size_t v) -> const Mat4 & { return skin_m.empty() ? world : skin_m[v]; };
    const bool world_flip = det3(world) < 0.0;
    /* a mirroring transform turns the winding: per triangle where skinned */
    auto flips = [&](size_t corner) { return skin_m.empty() ? world_flip : det3(skin_m[corner]) < 0.0; };
    double world_nm[9];
    normal_matrix(world, world_nm);

    auto world_vertex = [&](size_t v, lpv_vertex &out) {
        const Mat4 &mv = mat_of(v);
        double lp[3] = {pos[v * 3], pos[v * 3 + 1], pos[v * 3 + 2]}, wp[3];
        xform_point(mv, lp, wp);
        for (int k = 0; k < 3; k++) {
            out.position[k] = float(wp[k]);
            if (!std::isfinite(out.position[k]))
                fail("mesh %d primitive %d: world position of vertex %zu is not finite (NaN or Inf)", mesh, prim, v);
        }
        out.uv[0] = uv.empty() ? 0.0f : uv[v * 2];
        out.uv[1] = uv.empty() ? 0.0f : uv[v * 2 + 1];
        if (!std::isfinite(out.uv[0]) || !std::isfinite(out.uv[1]))
            out.uv[0] = out.uv[1] = 0.0f;
        for (int k = 0; k < 4; k++) {
            const float c = col.empty() || k >= col_comps ? 1.0f : col[v * size_t(col_comps) + size_t(k)];
            out.color[k] = std::isfinite(c) ? std::min(std::max(c, 0.0f), 1.0f) : 1.0f;
        }
        out.uv1[0] = uv1.empty() ? 0.0f : uv1[v * 2];
        out.uv1[1] = uv1.empty() ? 0.0f : uv1[v * 2 + 1];
        if (!std::isfinite(out.uv1[0]) || !std::isfinite(out.uv1[1]))
            out.uv1[0] = out.uv1[1] = 0.0f;
        /* TANGENT: xyz moves with the model matrix, w (handedness) flips with
         * a mirroring one; a degenerate or non-finite tangent is dropped (the
         * shader then builds its own frame) */
        out.tangent[0] = out.tangent[1] = out.tangent[2] = out.tangent[3] = 0.0f;
        if (!tan.empty()) {
            double lt[3] = {tan[v * 4], tan[v * 4 + 1], tan[v * 4 + 2]}, wt[3];
            xform_dir(mv, lt, wt);
            const double w = tan[v * 4 + 3];
            if (normalize3(wt) && std::isfinite(w)) {
                for (int k = 0; k < 3; k++)
                    out.tangent[k] = float(wt[k]);
                out.tangent[3] = ((w < 0.0) != (det3(mv) < 0.0)) ? -1.0f : 1.0f;
            }
        }
    };

    if (wire) {
        if (uint64_t(wire_indices.size()) + seg.size() > kMaxTriangles * 3 ||
            uint64_t(vertices.size()) + nv > kMaxVertices)
            fail("more than %llu vertices or point and line indices (absurd size)", (unsigned long long)kMaxVertices);
        lpv_draw w;
        w.first_index = uint32_t(wire_indices.size());
        w.index_count = uint32_t(seg.size());
        w.material = material;
        w.vertex_color = col.empty() ? 0 : 1;
        w.mode = mode == TINYGLTF_MODE_POINTS ? LPV_DRAW_POINTS : LPV_DRAW_LINES;
        const uint32_t base = uint32_t(vertices.size());
        vertices.resize(vertices.size() + nv);
        for (size_t v = 0; v < nv; v++) {
            lpv_vertex &out = vertices[base + v];
            world_vertex(v, out);
            out.normal[0] = out.normal[1] = out.normal[2] = 0.0f; /* shown unlit: no normal needed */
        }
        for (uint32_t i : seg)
            wire_indices.push_back(base + i);
        wire_draws.push_back(w);
        return;
    }

    const uint64_t add_vertices = nrm.empty() ? uint64_t(ntri) * 3 : uint64_t(nv);
    if (uint64_t(vertices.size()) + add_vertices > kMaxVertices)
        fail("more than %llu vertices (absurd size)", (unsigned long long)kMaxVertices);

    lpv_draw draw;
    draw.first_index = uint32_t(indices.size());
    draw.index_count = uint32_t(ntri * 3);
    draw.material = material;
    draw.vertex_color = col.empty() ? 0 : 1;
    draw.mode = LPV_DRAW_TRIANGLES;

    if (!nrm.empty()) {
        const uint32_t base = uint32_t(vertices.size());
        vertices.resize(vertices.size() + nv);
        for (size_t v = 0; v < nv; v++) {
            lpv_vertex &out = vertices[base + v];
            world_vertex(v, out);
            double vnm[9];
            if (!skin_m.empty())
                normal_matrix(skin_m[v], vnm);
            const double *nm = skin_m.empty() ? world_nm : vnm;
            double ln[3] = {nrm[v * 3], nrm[v * 3 + 1], nrm[v * 3 + 2]}, wn[3];
            for (int r = 0; r < 3; r++)
                wn[r] = nm[r * 3] * ln[0] + nm[r * 3 + 1] * ln[1] + nm[r * 3 + 2] * ln[2];
            if (!normalize3(wn))
                wn[0] = wn[1] = wn[2] = 0.0; /* degenerate normal: kept as zero */
            for (int k = 0; k < 3; k++)
                out.normal[k] = float(wn[k]);
        }
        indices.reserve(indices.size() + ntri * 3);
        for (size_t t = 0; t < ntri; t++) {
            uint32_t a = tri[t * 3], b = tri[t * 3 + 1], c = tri[t * 3 + 2];
            if (flips(a))
                std::swap(b, c);
            indices.insert(indices.end(), {base + a, base + b, base + c});
        }
    } else {
        /* No normals: flat per triangle from the (world) winding; vertices un-shared. */
        vertices.reserve(vertices.size() + ntri * 3);
        indices.reserve(indices.size() + ntri * 3);
        for (size_t t = 0; t < ntri; t++) {
            uint32_t corner[3] = {tri[t * 3], tri[t * 3 + 1], tri[t * 3 + 2]};
            if (flips(corner[0]))
                std::swap(corner[1], corner[2]);
            lpv_vertex vx[3];
            memset(vx, 0, sizeof vx);
            for (int k = 0; k < 3; k++)
                world_vertex(corner[k], vx[k]);
            double e1[3], e2[3], n[3];
            for (int k = 0; k < 3; k++) {
                e1[k] = double(vx[1].position[k]) - vx[0].position[k];
                e2[k] = double(vx[2].position[k]) - vx[0].position[k];
            }
            n[0] = e1[1] * e2[2] - e1[2] * e2[1];
            n[1] = e1[2] * e2[0] - e1[0] * e2[2];
            n[2] = e1[0] * e2[1] - e1[1] * e2[0];
            if (!normalize3(n))
                n[0] = n[1] = n[2] = 0.0;
            const uint32_t base = uint32_t(vertices.size());
            for (int k = 0; k < 3; k++) {
                for (int j = 0; j < 3; j++)
                    vx[k].normal[j] = float(n[j]);
                vertices.push_back(vx[k]);
            }
            indices.insert(indices.end(), {base, base + 1, base + 2});
        }
    }
    draws.push_back(draw);
}

} // namespace lpv_gltf
