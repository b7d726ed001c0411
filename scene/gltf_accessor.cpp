/*
 * gltf_accessor.cpp - the Builder's reading of binary data (gltf_internal.hpp):
 * buffer views (EXT_meshopt_compression ones decoded once) and accessors of
 * every component type glTF allows, normalized or not, sparse or not. Every
 * range is checked before anything is allocated or read; tinygltf checks none.
 */
#include "gltf_internal.hpp"
#include "gltf_compressed.hpp"

#include <algorithm>
#include <cstring>
#include <limits>

namespace lpv_gltf {

namespace {

size_t component_size(int ctype)
{
    switch (ctype) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
        return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
        return 4;
    default:
        return 0; /* INT and DOUBLE are not glTF 2.0 accessor types */
    }
}

int type_components(int type)
{
    switch (type) {
    case TINYGLTF_TYPE_SCALAR:
        return 1;
    case TINYGLTF_TYPE_VEC2:
        return 2;
    case TINYGLTF_TYPE_VEC3:
        return 3;
    case TINYGLTF_TYPE_VEC4:
        return 4;
    case TINYGLTF_TYPE_MAT4: /* skins' inverse bind matrices; 4-byte components need no column padding */
        return 16;
    default:
        return 0;
    }
}

/* A component of type I at p (unaligned) as a double. Normalized integers
 * map to [0, 1] (unsigned) or [-1, 1] (signed: the most negative value clamps
 * to -1, as glTF says); floats are never normalized. */
template <class I> double component(const unsigned char *p, bool normalized)
{
    I v;
    memcpy(&v, p, sizeof v);
    if (!normalized || !std::numeric_limits<I>::is_integer)
        return double(v);
    const double d = double(v) / double(std::numeric_limits<I>::max());
    return std::numeric_limits<I>::is_signed ? std::max(d, -1.0) : d;
}

double read_component(const unsigned char *p, int ctype, bool normalized)
{
    switch (ctype) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
        return component<int8_t>(p, normalized);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return component<uint8_t>(p, normalized);
    case TINYGLTF_COMPONENT_TYPE_SHORT:
        return component<int16_t>(p, normalized);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
        return component<uint16_t>(p, normalized);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
        return component<uint32_t>(p, normalized);
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
        return component<float>(p, normalized);
    default:
        return 0.0;
    }
}

const char *type_name(int ncomp)
{
    static const char *names[] = {"?", "SCALAR", "VEC2", "VEC3", "VEC4"};
    return ncomp == 16 ? "MAT4" : ncomp >= 0 && ncomp <= 4 ? names[ncomp] : "?";
}

} // namespace

Builder::View Builder::view(int bv_index, const char *what, int owner)
{
    if (bv_index < 0 || size_t(bv_index) >= m_.bufferViews.size())
        fail("%s %d refers to bufferView %d, which does not exist (out of range)", what, owner, bv_index);
    const tinygltf::BufferView &bv = m_.bufferViews[size_t(bv_index)];
    if (bv.buffer < 0 || size_t(bv.buffer) >= m_.buffers.size())
        fail("bufferView %d refers to buffer %d, which does not exist (out of range)", bv_index, bv.buffer);
    if (bv.extensions.count("EXT_meshopt_compression")) {
        /* decoded once; the view's own range is the (maybe empty) fallback */
        auto it = meshopt_.find(bv_index);
        if (it == meshopt_.end()) {
            std::vector<unsigned char> data;
            size_t stride = 0;
            std::string e = lpv_gltf::meshopt_decode(m_, bv_index, size_t(kMaxFileBytes), &data, &stride);
            if (!e.empty())
                fail("%s", e.c_str());
            it = meshopt_.emplace(bv_index, std::move(data)).first;
        }
        return View{it->second.data(), it->second.size(), bv.byteStride};
    }
    const tinygltf::Buffer &b = m_.buffers[size_t(bv.buffer)];
    size_t have = b.data.size();
    if (bv.byteOffset > have || bv.byteLength > have - bv.byteOffset)
        fail("bufferView %d (offset %zu, length %zu) is out of range of buffer %d (%zu bytes)", bv_index,
             bv.byteOffset, bv.byteLength, bv.buffer, have);
    return View{b.data.data() + bv.byteOffset, bv.byteLength, bv.byteStride};
}

void Builder::check_buffer_views()
{
    for (size_t i = 0; i < m_.bufferViews.size(); i++)
        (void)view(int(i), "bufferView", int(i));
}

template <class T> void Builder::read_accessor(int index, int want_ncomp, const char *what, std::vector<T> &out)
{
    if (index < 0 || size_t(index) >= m_.accessors.size())
        fail("%s accessor %d does not exist (out of range)", what, index);
    const tinygltf::Accessor &a = m_.accessors[size_t(index)];
    int ncomp = type_components(a.type);
    if (ncomp != want_ncomp)
        fail("%s accessor %d must be %s", what, index, type_name(want_ncomp));
    size_t csize = component_size(a.componentType);
    if (csize == 0)
        fail("%s accessor %d has unsupported componentType %d", what, index, a.componentType);
    if (a.count > kMaxAccessorCount)
        fail("%s accessor %d: count %zu is over the limit of %llu elements (absurd size)", what, index, a.count,
             (unsigned long long)kMaxAccessorCount);
    const size_t elem = csize * size_t(ncomp);

    /* Every range is checked before anything is allocated or read. */
    View v = {nullptr, 0, 0};
    size_t stride = elem;
    if (a.bufferView >= 0) {
        v = view(a.bufferView, "accessor", index);
        stride = v.stride ? v.stride : elem;
        if (stride < elem)
            fail("accessor %d: byteStride %zu is smaller than its element (%zu bytes)", index, stride, elem);
        if (a.count > 0) {
            size_t span, end;
            if (__builtin_mul_overflow(a.count - 1, stride, &span) || __builtin_add_overflow(span, elem, &span) ||
                __builtin_add_overflow(span, a.byteOffset, &end))
                fail("accessor %d: count * stride overflows (out of range)", index);
            if (end > v.length)
                fail("accessor %d (offset %zu, count %zu, stride %zu) is out of range of bufferView %d (%zu bytes)",
                     index, a.byteOffset, a.count, stride, a.bufferView, v.length);
        }
    } else if (a.bufferView != -1) {
        fail("accessor %d refers to bufferView %d, which does not exist (out of range)", index, a.bufferView);
    }
    View iv = {nullptr, 0, 0}, vv = {nullptr, 0, 0};
    size_t ioff = 0, voff = 0, isize = 0;
    int ictype = 0;
    const int sc = a.sparse.isSparse ? a.sparse.count : 0;
    if (a.sparse.isSparse) {
        if (sc <= 0 || size_t(sc) > a.count)
            fail("accessor %d: sparse count %d is out of range (accessor count %zu)", index, sc, a.count);
        ictype = a.sparse.indices.componentType;
        isize = component_size(ictype);
        if (ictype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && ictype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
            ictype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            fail("accessor %d: sparse indices have unsupported componentType %d", index, ictype);
        iv = view(a.sparse.indices.bufferView, "sparse indices of accessor", index);
        vv = view(a.sparse.values.bufferView, "sparse values of accessor", index);
        if (a.sparse.indices.byteOffset < 0 || a.sparse.values.byteOffset < 0)
            fail("accessor %d: negative sparse byteOffset", index);
        ioff = size_t(a.sparse.indices.byteOffset);
        voff = size_t(a.sparse.values.byteOffset);
        if (ioff > iv.length || size_t(sc) * isize > iv.length - ioff)
            fail("accessor %d: sparse indices are out of range of bufferView %d", index, a.sparse.indices.bufferView);
        if (voff > vv.length || size_t(sc) * elem > vv.length - voff)
            fail("accessor %d: sparse values are out of range of bufferView %d", index, a.sparse.values.bufferView);
    }

    out.assign(a.count * size_t(ncomp), T(0));
    if (a.bufferView >= 0) {
        const unsigned char *base = v.data + a.byteOffset;
        for (size_t i = 0; i < a.count; i++)
            for (int c = 0; c < ncomp; c++)
                out[i * size_t(ncomp) + size_t(c)] =
                    T(read_component(base + i * stride + size_t(c) * csize, a.componentType, a.normalized));
    }

    if (a.sparse.isSparse) {
        for (size_t s = 0; s < size_t(sc); s++) {
            double di = read_component(iv.data + ioff + s * isize, ictype, false);
            if (!(di < double(a.count)))
                fail("accessor %d: sparse index %.0f is out of range (count %zu)", index, di, a.count);
            size_t target = size_t(di);
            for (int c = 0; c < ncomp; c++)
                out[target * size_t(ncomp) + size_t(c)] =
                    T(read_component(vv.data + voff + s * elem + size_t(c) * csize, a.componentType, a.normalized));
        }
    }
}

void Builder::read_indices(int index, std::vector<uint32_t> &out)
{
    if (index < 0 || size_t(index) >= m_.accessors.size())
        fail("indices accessor %d does not exist (out of range)", index);
    int ct = m_.accessors[size_t(index)].componentType;
    if (ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
        fail("indices accessor %d has componentType %d; indices must be UNSIGNED_BYTE, UNSIGNED_SHORT or "
             "UNSIGNED_INT",
             index, ct);
    /* Indices are never normalized; read_component only normalizes when asked. */
    std::vector<double> tmp;
    if (m_.accessors[size_t(index)].normalized)
        fail("indices accessor %d must not be normalized", index);
    read_accessor(index, 1, "indices", tmp);
    out.resize(tmp.size());
    for (size_t i = 0; i < tmp.size(); i++)
        out[i] = uint32_t(tmp[i]);
}

/* The mesh builder's instance (gltf_mesh.cpp); read_indices and the
 * animations (gltf_animation.cpp) use <double>. */
template void Builder::read_accessor<float>(int, int, const char *, std::vector<float> &);
template void Builder::read_accessor<double>(int, int, const char *, std::vector<double> &);

} // namespace lpv_gltf
