/*
 * gltf_transform.cpp - node transforms (gltf_internal.hpp): 4x4 matrices in
 * glTF's column-major order, a node's matrix or TRS with every number
 * checked, and the caller's overrides of them (lpv_gltf_load_memory_ex).
 */
#include "gltf_internal.hpp"

#include <cmath>

namespace lpv_gltf {

Mat4 identity()
{
    Mat4 r{};
    r.m[0] = r.m[5] = r.m[10] = r.m[15] = 1.0;
    return r;
}

Mat4 mul(const Mat4 &a, const Mat4 &b)
{
    Mat4 r{};
    for (int c = 0; c < 4; c++)
        for (int row = 0; row < 4; row++) {
            double s = 0.0;
            for (int k = 0; k < 4; k++)
                s += a.m[k * 4 + row] * b.m[c * 4 + k];
            r.m[c * 4 + row] = s;
        }
    return r;
}

void xform_point(const Mat4 &a, const double p[3], double out[3])
{
    for (int r = 0; r < 3; r++)
        out[r] = a.m[r] * p[0] + a.m[4 + r] * p[1] + a.m[8 + r] * p[2] + a.m[12 + r];
}

void xform_dir(const Mat4 &a, const double v[3], double out[3])
{
    for (int r = 0; r < 3; r++)
        out[r] = a.m[r] * v[0] + a.m[4 + r] * v[1] + a.m[8 + r] * v[2];
}

double det3(const Mat4 &a)
{
    const double *m = a.m;
    return m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) +
           m[8] * (m[1] * m[6] - m[5] * m[2]);
}

/* The cofactor matrix times the determinant's sign. */
void normal_matrix(const Mat4 &a, double n[9])
{
    const double *m = a.m;
    /* A[r][c] = m[c*4+r]; cofactor C[r][c]. */
    auto A = [m](int r, int c) { return m[c * 4 + r]; };
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            int r1 = (r + 1) % 3, r2 = (r + 2) % 3, c1 = (c + 1) % 3, c2 = (c + 2) % 3;
            n[r * 3 + c] = A(r1, c1) * A(r2, c2) - A(r1, c2) * A(r2, c1);
        }
    double d = det3(a);
    if (d < 0.0)
        for (int i = 0; i < 9; i++)
            n[i] = -n[i];
}

bool normalize3(double v[3])
{
    double l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(l > 0.0) || !std::isfinite(l))
        return false;
    v[0] /= l;
    v[1] /= l;
    v[2] /= l;
    return true;
}

bool finite_all(const std::vector<double> &v)
{
    for (double x : v)
        if (!std::isfinite(x))
            return false;
    return true;
}

Mat4 node_local(const tinygltf::Node &n, int index)
{
    if (!n.matrix.empty()) {
        if (n.matrix.size() != 16 || !finite_all(n.matrix))
            fail("node %d: \"matrix\" must hold 16 finite numbers", index);
        Mat4 r;
        for (int i = 0; i < 16; i++)
            r.m[i] = n.matrix[size_t(i)];
        return r;
    }
    double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
    if (!n.translation.empty()) {
        if (n.translation.size() != 3 || !finite_all(n.translation))
            fail("node %d: \"translation\" must hold 3 finite numbers", index);
        for (int i = 0; i < 3; i++)
            t[i] = n.translation[size_t(i)];
    }
    if (!n.rotation.empty()) {
        if (n.rotation.size() != 4 || !finite_all(n.rotation))
            fail("node %d: \"rotation\" must hold 4 finite numbers", index);
        double l = 0;
        for (int i = 0; i < 4; i++) {
            q[i] = n.rotation[size_t(i)];
            l += q[i] * q[i];
        }
        l = std::sqrt(l);
        if (l > 0 && std::isfinite(l))
            for (double &c : q)
                c /= l;
        else
            q[0] = q[1] = q[2] = 0, q[3] = 1;
    }
    if (!n.scale.empty()) {
        if (n.scale.size() != 3 || !finite_all(n.scale))
            fail("node %d: \"scale\" must hold 3 finite numbers", index);
        for (int i = 0; i < 3; i++)
            s[i] = n.scale[size_t(i)];
    }
    double x = q[0], y = q[1], z = q[2], w = q[3];
    double R[3][3] = {
        {1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
        {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
        {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)},
    };
    Mat4 r = identity();
    for (int c = 0; c < 3; c++)
        for (int row = 0; row < 3; row++)
            r.m[c * 4 + row] = R[row][c] * s[c];
    r.m[12] = t[0];
    r.m[13] = t[1];
    r.m[14] = t[2];
    return r;
}

void apply_node_overrides(tinygltf::Model &model, const lpv_gltf_node_override *overrides, size_t count)
{
    for (size_t i = 0; i < count; ++i) {
        const lpv_gltf_node_override &o = overrides[i];
        if (o.node < 0 || size_t(o.node) >= model.nodes.size())
            fail("node override %zu: node %d does not exist (the file has %zu nodes)", i, o.node,
                 model.nodes.size());
        tinygltf::Node &n = model.nodes[size_t(o.node)];
        if (o.has_matrix) {
            n.matrix.assign(o.matrix, o.matrix + 16);
            n.translation.clear();
            n.rotation.clear();
            n.scale.clear();
            continue;
        }
        if ((o.has_translation || o.has_rotation || o.has_scale) && !n.matrix.empty()) {
            /* a node given as a matrix gets identity TRS parts it did not override */
            n.matrix.clear();
        }
        if (o.has_translation)
            n.translation.assign(o.translation, o.translation + 3);
        if (o.has_rotation)
            n.rotation.assign(o.rotation, o.rotation + 4);
        if (o.has_scale)
            n.scale.assign(o.scale, o.scale + 3);
    }
}

} // namespace lpv_gltf
