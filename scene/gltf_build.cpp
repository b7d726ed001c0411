/*
 * gltf_build.cpp - the Builder's walk (gltf_internal.hpp): refuses required
 * extensions lpvd lacks, checks every buffer view and that the nodes form a
 * forest (tinygltf checks neither), converts the materials, then walks the
 * loaded scene's nodes (the default scene, else the first, else every root)
 * with their world transforms into meshes, cameras and lights, and last names
 * what of the file lpvd does not use (gltf_features.hpp).
 */
#include "gltf_internal.hpp"
#include "gltf_features.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

namespace lpv_gltf {

Builder::~Builder()
{
    for (lpv_texture &t : textures)
        free(t.rgba8);
}

/* The hierarchy must be a forest: children in range, one parent at most, no
 * cycles, at most kMaxNodeDepth levels. tinygltf checks none of this. */
void Builder::check_node_graph()
{
    const size_t n = m_.nodes.size();
    std::vector<int> parent(n, -1);
    for (size_t i = 0; i < n; i++) {
        for (int c : m_.nodes[i].children) {
            if (c < 0 || size_t(c) >= n)
                fail("node %zu has child %d, which does not exist (out of range)", i, c);
            if (size_t(c) == i)
                fail("node %zu lists itself as its child (node cycle)", i);
            if (parent[size_t(c)] != -1)
                fail("node %d has more than one parent (nodes %d and %zu); the node graph must be a tree (cycle or "
                     "shared child)",
                     c, parent[size_t(c)], i);
            parent[size_t(c)] = int(i);
        }
    }
    /* Every node must lead up to a root within n steps; otherwise it hangs off
     * a cycle. Depth is checked while walking down from the roots. */
    std::vector<unsigned char> state(n, 0); /* 0 unknown, 1 reaches a root */
    std::vector<size_t> path;
    for (size_t i = 0; i < n; i++) {
        path.clear();
        size_t cur = i;
        while (state[cur] == 0 && parent[cur] != -1) {
            path.push_back(cur);
            if (path.size() > n)
                fail("node %zu is part of a node cycle", i);
            cur = size_t(parent[cur]);
        }
        state[cur] = 1;
        for (size_t p : path)
            state[p] = 1;
    }
    /* Depth from each root (iterative). */
    std::vector<std::pair<size_t, int>> stack;
    for (size_t i = 0; i < n; i++) {
        if (parent[i] != -1)
            continue;
        stack.push_back({i, 1});
        while (!stack.empty()) {
            auto [node, depth] = stack.back();
            stack.pop_back();
            if (depth > kMaxNodeDepth)
                fail("the node hierarchy under node %zu is deeper than %d levels", i, kMaxNodeDepth);
            for (int c : m_.nodes[node].children)
                stack.push_back({size_t(c), depth + 1});
        }
    }
}

void Builder::add_mesh(int mesh, const Mat4 &world, const Deform &d)
{
    if (mesh < 0 || size_t(mesh) >= m_.meshes.size())
        fail("mesh %d does not exist (out of range)", mesh);
    const tinygltf::Mesh &gm = m_.meshes[size_t(mesh)];
    for (size_t i = 0; i < gm.primitives.size(); i++)
        add_primitive(gm.primitives[i], mesh, int(i), world, d);
}

/* Every node's world transform, from the roots of the forest down
 * (check_node_graph made it one), with the caller's and the animation's
 * overrides already in the model. */
void Builder::compute_node_worlds()
{
    const size_t n = m_.nodes.size();
    node_world_.assign(n, identity());
    std::vector<unsigned char> is_child(n, 0);
    for (const auto &node : m_.nodes)
        for (int c : node.children)
            is_child[size_t(c)] = 1;
    std::vector<std::pair<int, Mat4>> stack;
    for (size_t i = 0; i < n; i++)
        if (!is_child[i])
            stack.push_back({int(i), identity()});
    while (!stack.empty()) {
        auto [node, parent] = stack.back();
        stack.pop_back();
        const Mat4 w = mul(parent, node_local(m_.nodes[size_t(node)], node));
        node_world_[size_t(node)] = w;
        for (int c : m_.nodes[size_t(node)].children)
            stack.push_back({c, w});
    }
}

/* Node `node`'s morph weights and skinning matrices (Deform). */
Deform Builder::deform_of(int node)
{
    const tinygltf::Node &n = m_.nodes[size_t(node)];
    Deform d;
    const tinygltf::Mesh &gm = m_.meshes[size_t(n.mesh)];
    d.weights = !n.weights.empty() ? n.weights : gm.weights;
    for (size_t k = 0; k < d.weights.size(); k++)
        if (!std::isfinite(d.weights[k]))
            fail("node %d: morph weight %zu is not finite", node, k);
    if (n.skin < 0)
        return d;
    if (size_t(n.skin) >= m_.skins.size())
        fail("node %d: skin %d does not exist (out of range)", node, n.skin);
    const tinygltf::Skin &sk = m_.skins[size_t(n.skin)];
    if (sk.joints.empty())
        fail("skin %d has no joints", n.skin);
    std::vector<double> ibm;
    if (sk.inverseBindMatrices >= 0) {
        if (size_t(sk.inverseBindMatrices) < m_.accessors.size() &&
            m_.accessors[size_t(sk.inverseBindMatrices)].componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
            fail("skin %d: inverseBindMatrices must be MAT4 FLOAT", n.skin);
        const std::string what = strf("skin %d inverseBindMatrices", n.skin);
        read_accessor(sk.inverseBindMatrices, 16, what.c_str(), ibm);
        if (ibm.size() < sk.joints.size() * 16)
            fail("skin %d: inverseBindMatrices holds %zu matrices for %zu joints", n.skin, ibm.size() / 16,
                 sk.joints.size());
    }
    for (size_t j = 0; j < sk.joints.size(); j++) {
        const int joint = sk.joints[j];
        if (joint < 0 || size_t(joint) >= m_.nodes.size())
            fail("skin %d: joint %zu is node %d, which does not exist (out of range)", n.skin, j, joint);
        Mat4 inv = identity();
        if (!ibm.empty())
            for (int k = 0; k < 16; k++) {
                inv.m[k] = ibm[j * 16 + size_t(k)];
                if (!std::isfinite(inv.m[k]))
                    fail("skin %d: inverse bind matrix %zu is not finite", n.skin, j);
            }
        d.joints.push_back(mul(node_world_[size_t(joint)], inv));
    }
    return d;
}

void Builder::visit(int node, const Mat4 &parent, int depth)
{
    if (depth > kMaxNodeDepth)
        fail("the node hierarchy is deeper than %d levels", kMaxNodeDepth);
    if (node < 0 || size_t(node) >= m_.nodes.size())
        fail("node %d does not exist (out of range)", node);
    if (visited_[size_t(node)])
        fail("node %d is reached twice from the scene (node cycle or shared subtree)", node);
    visited_[size_t(node)] = 1;
    const tinygltf::Node &n = m_.nodes[size_t(node)];
    const Mat4 world = mul(parent, node_local(n, node));
    for (int k = 0; k < 16; k++)
        if (!std::isfinite(world.m[k]))
            fail("node %d: world transform is not finite (NaN or Inf)", node);

    if (n.mesh >= 0) {
        if (size_t(n.mesh) >= m_.meshes.size())
            fail("node %d: mesh %d does not exist (out of range)", node, n.mesh);
        /* a skinned mesh moves with its joints alone (gltf_mesh.cpp): the
         * node's own transform is not applied (glTF 2.0, "Skins") */
        add_mesh(n.mesh, world, deform_of(node));
    } else if (n.mesh != -1)
        fail("node %d: mesh %d does not exist (out of range)", node, n.mesh);
    if (n.camera >= 0)
        add_camera(node, n.camera, world);
    else if (n.camera != -1)
        fail("node %d: camera %d does not exist (out of range)", node, n.camera);
    auto ext = n.extensions.find("KHR_lights_punctual");
    if (ext != n.extensions.end() && ext->second.IsObject() && ext->second.Has("light")) {
        const tinygltf::Value &v = ext->second.Get("light");
        double d = v.IsNumber() ? v.GetNumberAsDouble() : -1.0;
        if (!(d >= 0.0 && d < double(m_.lights.size())) || d != std::floor(d))
            fail("node %d: KHR_lights_punctual light %s does not exist (out of range)", node,
                 v.IsNumber() ? strf("%g", d).c_str() : "(not a number)");
        add_light(node, int(d), world);
    }
    for (int c : n.children)
        visit(c, world, depth + 1);
}

void Builder::build()
{
    std::string unsupported;
    for (const std::string &e : m_.extensionsRequired)
        if (!extension_supported(e))
            unsupported += (unsupported.empty() ? "" : ", ") + show(e);
    if (!unsupported.empty())
        fail("the file requires extension%s lpvd does not implement: %s (extensionsRequired)",
             unsupported.find(',') == std::string::npos ? "" : "s", unsupported.c_str());
    check_buffer_views();
    check_node_graph();
    convert_materials();

    std::vector<int> roots;
    int scene = m_.defaultScene;
    if (scene >= 0 && size_t(scene) >= m_.scenes.size())
        fail("default scene %d does not exist (out of range)", scene);
    if (scene < 0 && !m_.scenes.empty())
        scene = 0;
    if (scene >= 0) {
        roots = m_.scenes[size_t(scene)].nodes;
    } else {
        std::vector<unsigned char> is_child(m_.nodes.size(), 0);
        for (const auto &n : m_.nodes)
            for (int c : n.children)
                is_child[size_t(c)] = 1; /* in range: check_node_graph */
        for (size_t i = 0; i < m_.nodes.size(); i++)
            if (!is_child[i])
                roots.push_back(int(i));
    }
    compute_node_worlds();
    visited_.assign(m_.nodes.size(), 0);
    const Mat4 id = identity();
    for (int r : roots)
        visit(r, id, 1);
    for (const std::string &w : unused_features(m_, scene, ctx_.played))
        ctx_.warn(w);
}

} // namespace lpv_gltf
