/*
 * test_gltf_compressed.cpp - compressed glTF geometry (issue 10): a small
 * curved grid is encoded here with the Debian libraries' encoders (Draco's
 * KHR_draco_mesh_compression, meshoptimizer's EXT_meshopt_compression with
 * and without the octahedral filter, as .glb and as .gltf with a fallback
 * buffer that has no data), loaded through lpv_gltf_load_memory, and
 * compared with the source vertices; corrupt streams are refused with the
 * extension named. C++ only for the encoders; the checks are cmocka's.
 */
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <draco/compression/encode.h>
#include <draco/mesh/triangle_soup_mesh_builder.h>
#include <meshoptimizer.h>

extern "C" {
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>

#include "gltf_load.h"
#include "scene.h"
}

namespace {

/* ---- the source mesh: a 5x5-vertex grid, y = 0.2 sin(x) cos(z) ---------------- */
struct Vertex {
    float p[3], n[3], uv[2];
};

struct Mesh {
    std::vector<Vertex> v;
    std::vector<uint32_t> idx;
};

Mesh grid()
{
    Mesh m;
    const int N = 5;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            Vertex v;
            float x = -1.0f + 0.5f * float(i), z = -1.0f + 0.5f * float(j);
            v.p[0] = x, v.p[1] = 0.2f * std::sin(x) * std::cos(z), v.p[2] = z;
            /* the height field's normal: (-dy/dx, 1, -dy/dz) */
            float nx = -0.2f * std::cos(x) * std::cos(z), nz = 0.2f * std::sin(x) * std::sin(z);
            float l = std::sqrt(nx * nx + 1.0f + nz * nz);
            v.n[0] = nx / l, v.n[1] = 1.0f / l, v.n[2] = nz / l;
            v.uv[0] = float(i) / float(N - 1), v.uv[1] = float(j) / float(N - 1);
            m.v.push_back(v);
        }
    for (int j = 0; j + 1 < N; j++)
        for (int i = 0; i + 1 < N; i++) {
            uint32_t a = uint32_t(j * N + i), b = a + 1, c = a + uint32_t(N), d = c + 1;
            /* counter-clockwise seen from +y */
            m.idx.insert(m.idx.end(), {a, c, d, a, d, b});
        }
    return m;
}

/* ---- glb / gltf assembly ------------------------------------------------------------ */
void put_le32(std::vector<unsigned char> &o, size_t at, uint32_t v)
{
    for (int k = 0; k < 4; k++)
        o[at + size_t(k)] = (unsigned char)(v >> (8 * k));
}

std::vector<unsigned char> make_glb(const std::string &json_in, const std::vector<unsigned char> &bin)
{
    std::string json = json_in;
    while (json.size() % 4)
        json += ' ';
    size_t bpad = (bin.size() + 3) & ~size_t(3);
    size_t total = 12 + 8 + json.size() + (bin.empty() ? 0 : 8 + bpad);
    std::vector<unsigned char> o(total, 0);
    memcpy(o.data(), "glTF", 4);
    put_le32(o, 4, 2);
    put_le32(o, 8, uint32_t(total));
    put_le32(o, 12, uint32_t(json.size()));
    memcpy(o.data() + 16, "JSON", 4);
    memcpy(o.data() + 20, json.data(), json.size());
    if (!bin.empty()) {
        size_t c = 20 + json.size();
        put_le32(o, c, uint32_t(bpad));
        memcpy(o.data() + c + 4, "BIN\0", 4);
        memcpy(o.data() + c + 8, bin.data(), bin.size());
    }
    return o;
}

std::string base64(const std::vector<unsigned char> &d)
{
    static const char *t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string s;
    for (size_t i = 0; i < d.size(); i += 3) {
        uint32_t v = uint32_t(d[i]) << 16 | (i + 1 < d.size() ? uint32_t(d[i + 1]) << 8 : 0) |
                     (i + 2 < d.size() ? d[i + 2] : 0);
        s += t[v >> 18 & 63];
        s += t[v >> 12 & 63];
        s += i + 1 < d.size() ? t[v >> 6 & 63] : '=';
        s += i + 2 < d.size() ? t[v & 63] : '=';
    }
    return s;
}

std::string load_err(const std::vector<unsigned char> &data, lpv_scene *s, const char *label)
{
    char err[512] = "";
    memset(s, 0, sizeof *s);
    if (lpv_gltf_load_memory(data.data(), data.size(), nullptr, label, s, err, sizeof err) != 0)
        return err;
    return "";
}

/* Every source triangle has a loaded one with the same corners (positions,
 * normals, uvs within tol), in the same winding; counts agree. */
void expect_same_triangles(const lpv_scene &s, const Mesh &m, float tol)
{
    assert_int_equal(s.index_count, m.idx.size());
    const size_t nt = m.idx.size() / 3;
    std::vector<char> used(nt, 0);
    auto close = [tol](const float *a, const float *b, int n) {
        for (int k = 0; k < n; k++)
            if (std::fabs(a[k] - b[k]) > tol)
                return false;
        return true;
    };
    auto same = [&](const lpv_vertex &a, const Vertex &b) {
        return close(a.position, b.p, 3) && close(a.normal, b.n, 3) && close(a.uv, b.uv, 2);
    };
    for (size_t t = 0; t < nt; t++) {
        const Vertex *src[3] = {&m.v[m.idx[t * 3]], &m.v[m.idx[t * 3 + 1]], &m.v[m.idx[t * 3 + 2]]};
        bool found = false;
        for (size_t u = 0; u < nt && !found; u++) {
            if (used[u])
                continue;
            const lpv_vertex *got[3] = {&s.vertices[s.indices[u * 3]], &s.vertices[s.indices[u * 3 + 1]],
                                        &s.vertices[s.indices[u * 3 + 2]]};
            for (int r = 0; r < 3 && !found; r++) /* the same triangle, any starting corner */
                if (same(*got[r], *src[0]) && same(*got[(r + 1) % 3], *src[1]) && same(*got[(r + 2) % 3], *src[2]))
                    found = true, used[u] = 1;
        }
        if (!found)
            fail_msg("source triangle %zu has no match among the loaded ones (tolerance %g)", t, double(tol));
    }
}

/* ---- Draco ------------------------------------------------------------------- */
struct DracoFile {
    std::vector<unsigned char> bitstream;
    int pos_id, nrm_id, uv_id;
};

DracoFile draco_encode(const Mesh &m)
{
    const size_t nf = m.idx.size() / 3;
    draco::TriangleSoupMeshBuilder b;
    b.Start(int(nf));
    const int pa = b.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
    const int na = b.AddAttribute(draco::GeometryAttribute::NORMAL, 3, draco::DT_FLOAT32);
    const int ta = b.AddAttribute(draco::GeometryAttribute::TEX_COORD, 2, draco::DT_FLOAT32);
    for (size_t f = 0; f < nf; f++) {
        const Vertex &a = m.v[m.idx[f * 3]], &c1 = m.v[m.idx[f * 3 + 1]], &c2 = m.v[m.idx[f * 3 + 2]];
        const draco::FaceIndex fi{uint32_t(f)};
        b.SetAttributeValuesForFace(pa, fi, a.p, c1.p, c2.p);
        b.SetAttributeValuesForFace(na, fi, a.n, c1.n, c2.n);
        b.SetAttributeValuesForFace(ta, fi, a.uv, c1.uv, c2.uv);
    }
    std::unique_ptr<draco::Mesh> mesh = b.Finalize();
    assert_non_null(mesh.get());
    draco::Encoder enc;
    enc.SetAttributeQuantization(draco::GeometryAttribute::POSITION, 16);
    enc.SetAttributeQuantization(draco::GeometryAttribute::NORMAL, 14);
    enc.SetAttributeQuantization(draco::GeometryAttribute::TEX_COORD, 14);
    draco::EncoderBuffer buf;
    const draco::Status st = enc.EncodeMeshToBuffer(*mesh, &buf);
    if (!st.ok())
        fail_msg("draco encoding failed: %s", st.error_msg());
    DracoFile f;
    f.bitstream.assign(buf.data(), buf.data() + buf.size());
    f.pos_id = int(mesh->attribute(pa)->unique_id());
    f.nrm_id = int(mesh->attribute(na)->unique_id());
    f.uv_id = int(mesh->attribute(ta)->unique_id());
    return f;
}

std::vector<unsigned char> draco_glb(const DracoFile &d, size_t points, size_t indices, bool required)
{
    char json[2048];
    snprintf(json, sizeof json,
             "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_draco_mesh_compression\"]%s,"
             "\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2},"
             "\"indices\":3,\"extensions\":{\"KHR_draco_mesh_compression\":{\"bufferView\":0,"
             "\"attributes\":{\"POSITION\":%d,\"NORMAL\":%d,\"TEXCOORD_0\":%d}}}}]}],"
             "\"accessors\":[{\"componentType\":5126,\"count\":%zu,\"type\":\"VEC3\"},"
             "{\"componentType\":5126,\"count\":%zu,\"type\":\"VEC3\"},"
             "{\"componentType\":5126,\"count\":%zu,\"type\":\"VEC2\"},"
             "{\"componentType\":5125,\"count\":%zu,\"type\":\"SCALAR\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":%zu}],\"buffers\":[{\"byteLength\":%zu}]}",
             required ? ",\"extensionsRequired\":[\"KHR_draco_mesh_compression\"]" : "", d.pos_id, d.nrm_id, d.uv_id,
             points, points, points, indices, d.bitstream.size(), (d.bitstream.size() + 3) & ~size_t(3));
    return make_glb(json, d.bitstream);
}

void test_draco_decodes(void **)
{
    const Mesh m = grid();
    const DracoFile d = draco_encode(m);
    printf("draco: %zu vertices, %zu indices -> %zu bytes\n", m.v.size(), m.idx.size(), d.bitstream.size());
    lpv_scene s;
    std::string e = load_err(draco_glb(d, m.v.size(), m.idx.size(), true), &s, "draco.glb");
    if (!e.empty())
        fail_msg("%s", e.c_str());
    /* 16-bit positions over 2 m: 3e-5 m; 14-bit normals and uvs: ~1e-3 */
    expect_same_triangles(s, m, 2e-3f);
    lpv_scene_free(&s);
}

void test_draco_corrupt_is_named(void **)
{
    const Mesh m = grid();
    DracoFile d = draco_encode(m);
    for (size_t i = 8; i < d.bitstream.size(); i++)
        d.bitstream[i] = (unsigned char)(d.bitstream[i] * 7u + 13u);
    lpv_scene s;
    std::string e = load_err(draco_glb(d, m.v.size(), m.idx.size(), true), &s, "bad-draco.glb");
    printf("corrupt draco -> %s\n", e.c_str());
    assert_false(e.empty());
    assert_non_null(strstr(e.c_str(), "bad-draco.glb: mesh 0 primitive 0: KHR_draco_mesh_compression"));
    /* damaged bitstreams (cut short, single bytes changed past the header):
     * loaded or refused with the extension named, never a crash */
    const DracoFile good = draco_encode(m);
    uint32_t rng = 12345;
    int refused = 0, loaded = 0;
    for (int k = 0; k < 300; k++) {
        DracoFile bad = good;
        rng = rng * 1664525u + 1013904223u;
        if (k % 3 == 0) {
            bad.bitstream.resize(1 + size_t(rng % (good.bitstream.size() - 1)));
        } else {
            size_t at = 12 + size_t(rng >> 8) % (good.bitstream.size() - 12);
            bad.bitstream[at] = (unsigned char)(bad.bitstream[at] ^ (1u + (rng >> 24) % 255u));
        }
        e = load_err(draco_glb(bad, m.v.size(), m.idx.size(), true), &s, "damaged.glb");
        if (e.empty()) {
            loaded++;
            lpv_scene_free(&s);
        } else {
            refused++;
            if (!strstr(e.c_str(), "KHR_draco_mesh_compression") && !strstr(e.c_str(), "out of range"))
                fail_msg("damaged bitstream %d: '%s' names neither the extension nor the range", k, e.c_str());
        }
    }
    printf("damaged draco bitstreams: %d refused, %d still decoded\n", refused, loaded);
    assert_true(refused > 0);
    /* an attribute id the bitstream lacks */
    d = draco_encode(m);
    d.nrm_id = 9;
    e = load_err(draco_glb(d, m.v.size(), m.idx.size(), true), &s, "bad-id.glb");
    printf("missing attribute -> %s\n", e.c_str());
    assert_non_null(strstr(e.c_str(), "KHR_draco_mesh_compression: attribute NORMAL: Draco id 9"));
}

/* ---- meshopt -------------------------------------------------------------------- */
struct MeshoptFile {
    std::vector<unsigned char> bin;
    std::string json;
};

/* The grid as EXT_meshopt_compression: interleaved vertices (ATTRIBUTES) or
 * positions + uvs with octahedral 8-bit normals in their own stream, and
 * TRIANGLES indices; the fallback buffer has no data. gltf: JSON with data
 * URIs instead of a BIN chunk. */
MeshoptFile meshopt_encode(const Mesh &m, bool oct_normals, bool corrupt)
{
    const size_t n = m.v.size(), ni = m.idx.size();
    MeshoptFile f;
    auto append = [&f](const std::vector<unsigned char> &d) {
        while (f.bin.size() % 4)
            f.bin.push_back(0);
        size_t at = f.bin.size();
        f.bin.insert(f.bin.end(), d.begin(), d.end());
        return at;
    };
    auto encode_vertices = [](const void *data, size_t count, size_t stride) {
        std::vector<unsigned char> out(meshopt_encodeVertexBufferBound(count, stride));
        out.resize(meshopt_encodeVertexBuffer(out.data(), out.size(), data, count, stride));
        return out;
    };
    std::vector<unsigned char> vbuf, nbuf;
    size_t vstride;
    if (!oct_normals) {
        vstride = sizeof(Vertex);
        vbuf = encode_vertices(m.v.data(), n, vstride);
    } else {
        struct PU {
            float p[3], uv[2], pad;
        };
        std::vector<PU> pu(n);
        std::vector<float> n4(n * 4);
        for (size_t i = 0; i < n; i++) {
            memcpy(pu[i].p, m.v[i].p, sizeof pu[i].p);
            memcpy(pu[i].uv, m.v[i].uv, sizeof pu[i].uv);
            pu[i].pad = 0.0f;
            memcpy(&n4[i * 4], m.v[i].n, 3 * sizeof(float));
            n4[i * 4 + 3] = 0.0f;
        }
        vstride = sizeof(PU);
        vbuf = encode_vertices(pu.data(), n, vstride);
        std::vector<unsigned char> oct(n * 4);
        meshopt_encodeFilterOct(oct.data(), n, 4, 8, n4.data());
        nbuf = encode_vertices(oct.data(), n, 4);
    }
    std::vector<unsigned char> ibuf(meshopt_encodeIndexBufferBound(ni, n));
    ibuf.resize(meshopt_encodeIndexBuffer(ibuf.data(), ibuf.size(), m.idx.data(), ni));
    if (corrupt)
        for (size_t i = 1; i < vbuf.size(); i++)
            vbuf[i] = (unsigned char)(vbuf[i] ^ 0x5a);
    const size_t vo = append(vbuf), io = append(ibuf), no = nbuf.empty() ? 0 : append(nbuf);
    const size_t fallback = n * vstride + ni * 4 + n * 4;
    char views[2048], attrs[256], acc[1024];
    snprintf(views, sizeof views,
             "{\"buffer\":1,\"byteOffset\":0,\"byteLength\":%zu,\"byteStride\":%zu,\"extensions\":{"
             "\"EXT_meshopt_compression\":{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,\"byteStride\":%zu,"
             "\"count\":%zu,\"mode\":\"ATTRIBUTES\"}}},"
             "{\"buffer\":1,\"byteOffset\":%zu,\"byteLength\":%zu,\"extensions\":{"
             "\"EXT_meshopt_compression\":{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,\"byteStride\":4,"
             "\"count\":%zu,\"mode\":\"TRIANGLES\"}}}",
             n * vstride, vstride, vo, vbuf.size(), vstride, n, n * vstride, ni * 4, io, ibuf.size(), ni);
    if (oct_normals)
        snprintf(views + strlen(views), sizeof views - strlen(views),
                 ",{\"buffer\":1,\"byteOffset\":%zu,\"byteLength\":%zu,\"byteStride\":4,\"extensions\":{"
                 "\"EXT_meshopt_compression\":{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,\"byteStride\":4,"
                 "\"count\":%zu,\"mode\":\"ATTRIBUTES\",\"filter\":\"OCTAHEDRAL\"}}}",
                 n * vstride + ni * 4, n * 4, no, nbuf.size(), n);
    if (!oct_normals) {
        snprintf(acc, sizeof acc,
                 "{\"bufferView\":0,\"byteOffset\":0,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC3\"},"
                 "{\"bufferView\":0,\"byteOffset\":12,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC3\"},"
                 "{\"bufferView\":0,\"byteOffset\":24,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC2\"},",
                 n, n, n);
    } else {
        snprintf(acc, sizeof acc,
                 "{\"bufferView\":0,\"byteOffset\":0,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC3\"},"
                 "{\"bufferView\":2,\"byteOffset\":0,\"componentType\":5120,\"normalized\":true,\"count\":%zu,"
                 "\"type\":\"VEC3\"},"
                 "{\"bufferView\":0,\"byteOffset\":12,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC2\"},",
                 n, n, n);
    }
    snprintf(acc + strlen(acc), sizeof acc - strlen(acc),
             "{\"bufferView\":1,\"componentType\":5125,\"count\":%zu,\"type\":\"SCALAR\"}", ni);
    snprintf(attrs, sizeof attrs, "{\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2}");
    char head[4096];
    snprintf(head, sizeof head,
             "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"EXT_meshopt_compression\"],"
             "\"extensionsRequired\":[\"EXT_meshopt_compression\"],"
             "\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":%s,\"indices\":3}]}],"
             "\"accessors\":[%s],\"bufferViews\":[%s],",
             attrs, acc, views);
    f.json = head;
    f.json += "\"buffers\":[{\"byteLength\":" + std::to_string(f.bin.size()) + "%URI%},{\"byteLength\":" +
              std::to_string(fallback) + ",\"extensions\":{\"EXT_meshopt_compression\":{\"fallback\":true}}}]}";
    return f;
}

std::vector<unsigned char> as_glb(const MeshoptFile &f)
{
    std::string j = f.json;
    j.replace(j.find("%URI%"), 5, "");
    return make_glb(j, f.bin);
}

std::vector<unsigned char> as_gltf(const MeshoptFile &f)
{
    std::string j = f.json;
    j.replace(j.find("%URI%"), 5, ",\"uri\":\"data:application/octet-stream;base64," + base64(f.bin) + "\"");
    return std::vector<unsigned char>(j.begin(), j.end());
}

void test_meshopt_decodes(void **)
{
    const Mesh m = grid();
    struct {
        const char *name;
        bool oct, glb;
        float tol;
    } cases[] = {
        {"meshopt.glb", false, true, 0.0f},
        {"meshopt.gltf", false, false, 0.0f},
        /* 8-bit octahedral normals: ~1/127 per component */
        {"meshopt-oct.glb", true, true, 0.02f},
    };
    for (const auto &c : cases) {
        MeshoptFile f = meshopt_encode(m, c.oct, false);
        lpv_scene s;
        std::string e = load_err(c.glb ? as_glb(f) : as_gltf(f), &s, c.name);
        if (!e.empty())
            fail_msg("%s", e.c_str());
        printf("%s: %zu bytes of compressed data; loaded %u vertices, %u indices\n", c.name, f.bin.size(),
               s.vertex_count, s.index_count);
        expect_same_triangles(s, m, c.tol > 0.0f ? c.tol : 1e-7f);
        if (c.tol == 0.0f) { /* lossless: the same vertices in the same order */
            assert_int_equal(s.vertex_count, m.v.size());
            for (size_t i = 0; i < m.idx.size(); i++)
                assert_int_equal(s.indices[i], m.idx[i]);
            for (size_t i = 0; i < m.v.size(); i++)
                assert_memory_equal(s.vertices[i].position, m.v[i].p, sizeof m.v[i].p);
        }
        lpv_scene_free(&s);
    }
}

void test_meshopt_corrupt_is_named(void **)
{
    const Mesh m = grid();
    MeshoptFile f = meshopt_encode(m, false, true);
    lpv_scene s;
    std::string e = load_err(as_glb(f), &s, "bad-meshopt.glb");
    printf("corrupt meshopt -> %s\n", e.c_str());
    assert_non_null(strstr(e.c_str(), "bad-meshopt.glb: bufferView 0: EXT_meshopt_compression"));
    /* a mode that does not exist */
    f = meshopt_encode(m, false, false);
    f.json.replace(f.json.find("\"TRIANGLES\""), 11, "\"STRIPS\"");
    e = load_err(as_glb(f), &s, "bad-mode.glb");
    printf("bad mode -> %s\n", e.c_str());
    assert_non_null(strstr(e.c_str(), "EXT_meshopt_compression: mode \"STRIPS\" is not"));
}

} // namespace

int main()
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_draco_decodes),
        cmocka_unit_test(test_draco_corrupt_is_named),
        cmocka_unit_test(test_meshopt_decodes),
        cmocka_unit_test(test_meshopt_corrupt_is_named),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
