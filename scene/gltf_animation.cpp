/*
 * gltf_animation.cpp - the file's animations (gltf_internal.hpp, Builder):
 * their node translation / rotation / scale / weights channels sampled at a
 * time into node overrides (lpv_gltf_load_file_animated), and their list
 * (lpv_gltf_animations). glTF 2.0, "Animations": LINEAR (rotations slerped
 * along the shortest path), STEP and CUBICSPLINE (Hermite, the tangents
 * scaled by the keyframe interval); before the first keyframe the first
 * value, after the last the last. Every channel, sampler and accessor an
 * animation plays is checked before anything is sampled, and a defect
 * refuses the file with "animation 2 ("Walk"): <problem>". Morph-target
 * "weights" channels become the node's weights (gltf_mesh.cpp morphs with
 * them); KHR_animation_pointer is skipped here and warned by
 * gltf_features.cpp.
 */
#include "gltf_internal.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <glm/gtc/quaternion.hpp>

namespace lpv_gltf {

namespace {

enum class Path { translation, rotation, scale, weights };
enum class Interp { linear, step, cubic };

/* One sampler's keyframes: times, and ncomp values per element (CUBICSPLINE:
 * in-tangent, value, out-tangent per keyframe). */
struct Keys {
    Interp interp = Interp::linear;
    int ncomp = 0;
    std::vector<double> in;
    std::vector<double> out;
};

/* "animation 2 (\"Walk\")", the name shown only when it is an identifier (show()). */
std::string animation_label(const tinygltf::Model &m, size_t a)
{
    const std::string &n = m.animations[a].name;
    std::string s = show(n);
    return n.empty() || s[0] != '"' ? strf("animation %zu", a) : strf("animation %zu (%s)", a, s.c_str());
}

/* Whether the channel animates through KHR_animation_pointer (path "pointer",
 * the extension on its target): skipped, warned by gltf_features.cpp. */
bool is_pointer_channel(const tinygltf::AnimationChannel &c)
{
    return c.target_path == "pointer" || c.target_extensions.count("KHR_animation_pointer") ||
           c.extensions.count("KHR_animation_pointer");
}

const double *element(const Keys &k, size_t i) { return k.out.data() + i * size_t(k.ncomp); }

void normalize4(double q[4])
{
    double l = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (l > 0.0 && std::isfinite(l))
        for (int i = 0; i < 4; i++)
            q[i] /= l;
}

/* Spherical interpolation of unit quaternions a -> b (glTF order x, y, z, w)
 * along the shortest arc: GLM's slerp (q and -q are the same rotation; nearly
 * equal keys fall back to a linear blend), renormalised. */
void slerp(const double a[4], const double b[4], double u, double out[4])
{
    const glm::dquat qa(a[3], a[0], a[1], a[2]), qb(b[3], b[0], b[1], b[2]); /* w first */
    const glm::dquat q = glm::slerp(qa, qb, u);
    out[0] = q.x;
    out[1] = q.y;
    out[2] = q.z;
    out[3] = q.w;
    normalize4(out);
}

/* Keys k sampled at time t into out[k.ncomp]; rotations come out unit length. */
void sample(const Keys &k, double t, bool rotation, double *out)
{
    const size_t n = k.in.size();
    const size_t stride = k.interp == Interp::cubic ? 3 : 1; /* elements per keyframe */
    const size_t value = k.interp == Interp::cubic ? 1 : 0;  /* the value's element within one */
    auto copy = [&](size_t key) {
        const double *v = element(k, key * stride + value);
        for (int c = 0; c < k.ncomp; c++)
            out[c] = v[c];
    };
    if (t <= k.in[0] || n == 1) {
        copy(0);
        return;
    }
    if (t >= k.in[n - 1]) {
        copy(n - 1);
        return;
    }
    /* k.in[i] <= t < k.in[i + 1] */
    const size_t i = size_t(std::upper_bound(k.in.begin(), k.in.end(), t) - k.in.begin()) - 1;
    const double td = k.in[i + 1] - k.in[i];
    const double u = (t - k.in[i]) / td;
    if (k.interp == Interp::step) {
        copy(i);
        return;
    }
    if (k.interp == Interp::linear) {
        const double *a = element(k, i), *b = element(k, i + 1);
        if (rotation)
            slerp(a, b, u, out);
        else
            for (int c = 0; c < k.ncomp; c++)
                out[c] = a[c] + u * (b[c] - a[c]);
        return;
    }
    /* CUBICSPLINE: p0 = v_i, m0 = td * b_i (its out-tangent), p1 = v_i+1,
     * m1 = td * a_i+1 (the next in-tangent). */
    const double *p0 = element(k, 3 * i + 1), *b0 = element(k, 3 * i + 2);
    const double *a1 = element(k, 3 * (i + 1)), *p1 = element(k, 3 * (i + 1) + 1);
    const double u2 = u * u, u3 = u2 * u;
    const double h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
    for (int c = 0; c < k.ncomp; c++)
        out[c] = h00 * p0[c] + h10 * td * b0[c] + h01 * p1[c] + h11 * td * a1[c];
    if (rotation)
        normalize4(out);
}

bool parse_index(const char *s, size_t *out)
{
    size_t v = 0, n = 0;
    for (; s[n]; n++) {
        if (s[n] < '0' || s[n] > '9' || n >= 9)
            return false;
        v = v * 10 + size_t(s[n] - '0');
    }
    *out = v;
    return n > 0;
}

/* "2 animations (0 \"Walk\", 1 \"Run\")" for a message, at most 8 named. */
std::string describe_animations(const tinygltf::Model &m)
{
    const size_t n = m.animations.size();
    std::string s = strf("%zu animation%s", n, n == 1 ? "" : "s");
    for (size_t a = 0; a < n && a < 8; a++) {
        std::string shown = show(m.animations[a].name);
        s += (a ? ", " : " (") + std::to_string(a) + (shown[0] == '"' ? " " + shown : std::string());
    }
    if (n > 8)
        s += strf(" and %zu more", n - 8);
    return n ? s + ")" : s;
}

/* A name from the file into a fixed-size field: control characters as '?',
 * cut before an embedded NUL and on a UTF-8 character boundary. */
void copy_clean(char *dst, size_t size, const std::string &src)
{
    size_t n = std::min(src.size(), size - 1);
    size_t z = src.find('\0');
    if (z != std::string::npos && z < n)
        n = z;
    if (n < src.size())
        while (n > 0 && (static_cast<unsigned char>(src[n]) & 0xC0) == 0x80)
            n--;
    for (size_t i = 0; i < n; i++) {
        unsigned char c = static_cast<unsigned char>(src[i]);
        dst[i] = (c < 0x20 || c == 0x7f) ? '?' : char(c);
    }
    dst[n] = '\0';
}

} // namespace

struct Builder::Animation {
    struct Channel {
        int node;
        Path path;
        int sampler;
    };
    std::vector<Channel> channels; /* translation / rotation / scale / weights */
    std::vector<Keys> samplers;    /* by sampler index; outputs read for those channels use */
    double duration = 0.0;         /* the largest input time of all its samplers */
};

void Builder::read_animation(size_t index, Animation &out)
{
    try {
        read_animation_parts(index, out);
    } catch (Failure &f) {
        f.msg = animation_label(m_, index) + ": " + f.msg;
        throw;
    }
}

/* read_animation without the animation's name in front of the messages. */
void Builder::read_animation_parts(size_t index, Animation &out)
{
    const tinygltf::Animation &ga = m_.animations[index];
    out = Animation();
    out.samplers.resize(ga.samplers.size());

    /* Every sampler's keyframe times: finite and strictly increasing. */
    for (size_t s = 0; s < ga.samplers.size(); s++) {
        const tinygltf::AnimationSampler &gs = ga.samplers[s];
        Keys &k = out.samplers[s];
        if (gs.interpolation == "LINEAR")
            k.interp = Interp::linear;
        else if (gs.interpolation == "STEP")
            k.interp = Interp::step;
        else if (gs.interpolation == "CUBICSPLINE")
            k.interp = Interp::cubic;
        else
            fail("sampler %zu: interpolation %s is not LINEAR, STEP or CUBICSPLINE", s,
                 show(gs.interpolation).c_str());
        if (gs.input < 0 || size_t(gs.input) >= m_.accessors.size())
            fail("sampler %zu: input accessor %d does not exist (out of range)", s, gs.input);
        const tinygltf::Accessor &ia = m_.accessors[size_t(gs.input)];
        if (ia.type != TINYGLTF_TYPE_SCALAR || ia.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
            fail("sampler %zu: input accessor %d must be SCALAR FLOAT (keyframe times in seconds)", s, gs.input);
        const std::string what = strf("sampler %zu: input", s);
        read_accessor(gs.input, 1, what.c_str(), k.in);
        if (k.in.empty())
            fail("sampler %zu: input accessor %d holds no keyframe times", s, gs.input);
        for (size_t i = 0; i < k.in.size(); i++) {
            if (!std::isfinite(k.in[i]))
                fail("sampler %zu: keyframe time %zu is not finite (input accessor %d)", s, i, gs.input);
            if (i > 0 && !(k.in[i] > k.in[i - 1]))
                fail("sampler %zu: keyframe times are not increasing: keyframe %zu at %g s follows one at %g s "
                     "(input accessor %d)",
                     s, i, k.in[i], k.in[i - 1], gs.input);
        }
        out.duration = std::max(out.duration, k.in.back());
    }

    /* The node channels, and the outputs of the samplers they use. */
    for (size_t c = 0; c < ga.channels.size(); c++) {
        const tinygltf::AnimationChannel &gc = ga.channels[c];
        if (is_pointer_channel(gc))
            continue; /* not supported: warned (gltf_features.cpp) */
        Path path;
        if (gc.target_path == "weights")
            path = Path::weights;
        else if (gc.target_path == "translation")
            path = Path::translation;
        else if (gc.target_path == "rotation")
            path = Path::rotation;
        else if (gc.target_path == "scale")
            path = Path::scale;
        else
            fail("channel %zu: target path %s is not translation, rotation, scale or weights", c,
                 show(gc.target_path).c_str());
        if (gc.sampler < 0 || size_t(gc.sampler) >= ga.samplers.size())
            fail("channel %zu: sampler %d does not exist (the animation has %zu sampler%s)", c, gc.sampler,
                 ga.samplers.size(), ga.samplers.size() == 1 ? "" : "s");
        if (gc.target_node < 0 || size_t(gc.target_node) >= m_.nodes.size())
            fail("channel %zu: target node %d does not exist (out of range; the file has %zu node%s)", c,
                 gc.target_node, m_.nodes.size(), m_.nodes.size() == 1 ? "" : "s");
        if (path != Path::weights && !m_.nodes[size_t(gc.target_node)].matrix.empty())
            fail("channel %zu: target node %d is given as a matrix; an animated node must use translation, "
                 "rotation and scale",
                 c, gc.target_node);
        if (path == Path::weights) {
            /* one weight per morph target of the node's mesh, per keyframe */
            const tinygltf::Node &tn = m_.nodes[size_t(gc.target_node)];
            const size_t targets = tn.mesh >= 0 && size_t(tn.mesh) < m_.meshes.size() &&
                                           !m_.meshes[size_t(tn.mesh)].primitives.empty()
                                       ? m_.meshes[size_t(tn.mesh)].primitives[0].targets.size()
                                       : 0;
            if (!targets) { /* nothing to weigh: the rest of the animation plays */
                ctx_.warn(strf("morph target weights channel (%s channel %zu): node %d's mesh has no morph targets; "
                               "ignored",
                               animation_label(m_, index).c_str(), c, gc.target_node));
                continue;
            }
            if (gc.sampler < 0 || size_t(gc.sampler) >= ga.samplers.size())
                fail("channel %zu: sampler %d does not exist", c, gc.sampler);
            const int s = gc.sampler;
            const tinygltf::AnimationSampler &gs = ga.samplers[size_t(s)];
            Keys &k = out.samplers[size_t(s)];
            if (gs.output < 0 || size_t(gs.output) >= m_.accessors.size())
                fail("sampler %d: output accessor %d does not exist (out of range)", s, gs.output);
            const tinygltf::Accessor &oa = m_.accessors[size_t(gs.output)];
            if (oa.type != TINYGLTF_TYPE_SCALAR ||
                !(oa.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT || oa.normalized))
                fail("channel %zu (weights): output accessor %d of sampler %d must be SCALAR FLOAT or normalized", c,
                     gs.output, s);
            out.channels.push_back({gc.target_node, path, s});
            if (k.ncomp == int(targets))
                continue;
            const std::string what = strf("sampler %d: output", s);
            std::vector<double> flat;
            read_accessor(gs.output, 1, what.c_str(), flat);
            const size_t keys = k.in.size(), per = k.interp == Interp::cubic ? 3 : 1;
            if (flat.size() != keys * per * targets)
                fail("sampler %d: output accessor %d holds %zu weights; %zu keyframes of %zu morph targets need %zu",
                     s, gs.output, flat.size(), keys, targets, keys * per * targets);
            for (size_t e = 0; e < flat.size(); e++)
                if (!std::isfinite(flat[e]))
                    fail("sampler %d: output weight %zu is not finite (output accessor %d)", s, e, gs.output);
            k.ncomp = int(targets);
            k.out = flat;
            continue;
        }

        const int s = gc.sampler;
        const tinygltf::AnimationSampler &gs = ga.samplers[size_t(s)];
        Keys &k = out.samplers[size_t(s)];
        const bool rotation = path == Path::rotation;
        const int want = rotation ? 4 : 3;
        if (gs.output < 0 || size_t(gs.output) >= m_.accessors.size())
            fail("sampler %d: output accessor %d does not exist (out of range)", s, gs.output);
        const tinygltf::Accessor &oa = m_.accessors[size_t(gs.output)];
        const int ct = oa.componentType;
        const bool float_ok = ct == TINYGLTF_COMPONENT_TYPE_FLOAT;
        const bool norm_ok = rotation && oa.normalized &&
                             (ct == TINYGLTF_COMPONENT_TYPE_BYTE || ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                              ct == TINYGLTF_COMPONENT_TYPE_SHORT || ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
        if (oa.type != (rotation ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3) || !(float_ok || norm_ok))
            fail("channel %zu (%s): output accessor %d of sampler %d must be %s", c, gc.target_path.c_str(),
                 gs.output, s,
                 rotation ? "VEC4 FLOAT or normalized BYTE / UNSIGNED_BYTE / SHORT / UNSIGNED_SHORT (a quaternion)"
                          : "VEC3 FLOAT");
        out.channels.push_back({gc.target_node, path, s});
        if (k.ncomp == want)
            continue; /* read and checked for an earlier channel */
        k.ncomp = want;
        const std::string what = strf("sampler %d: output", s);
        read_accessor(gs.output, want, what.c_str(), k.out);
        const size_t keys = k.in.size(), per = k.interp == Interp::cubic ? 3 : 1;
        const size_t elements = k.out.size() / size_t(want);
        if (elements != keys * per)
            fail("sampler %d: output accessor %d holds %zu elements; %s with %zu keyframes needs %zu%s", s,
                 gs.output, elements, gs.interpolation.c_str(), keys, keys * per,
                 per == 3 ? " (3 per keyframe: in-tangent, value, out-tangent)" : " (one per keyframe)");
        for (size_t e = 0; e < elements; e++) {
            const double *v = element(k, e);
            for (int i = 0; i < want; i++)
                if (!std::isfinite(v[i]))
                    fail("sampler %d: output element %zu is not finite (output accessor %d)", s, e, gs.output);
            if (rotation && (per == 1 || e % 3 == 1)) {
                double q[4] = {v[0], v[1], v[2], v[3]};
                if (q[0] == 0 && q[1] == 0 && q[2] == 0 && q[3] == 0)
                    fail("sampler %d: rotation %zu is not a unit quaternion (all zero; output accessor %d)", s,
                         e / per, gs.output);
                normalize4(q);
                std::copy(q, q + 4, k.out.begin() + std::ptrdiff_t(e * 4));
            }
        }
    }
}

std::vector<lpv_gltf_node_override> Builder::sample_animations(const lpv_gltf_animation_time &at,
                                                               std::vector<std::pair<int, std::vector<double>>> &weights)
{
    const size_t n = m_.animations.size();
    const bool every = !at.animation || !at.animation[0];
    const std::string asked = every ? std::string("every animation") : "animation " + show_uri(at.animation);
    if (!std::isfinite(at.time))
        fail("%s: time %g s is not finite", asked.c_str(), at.time);
    if (at.time < 0.0)
        fail("%s: time %g s is negative (times are seconds from the animation's start)", asked.c_str(), at.time);
    if (n == 0)
        fail("%s requested at %g s, but the file has no animations", asked.c_str(), at.time);

    std::vector<size_t> chosen;
    if (every) {
        for (size_t a = 0; a < n; a++)
            chosen.push_back(a);
    } else {
        for (size_t a = 0; a < n && chosen.empty(); a++)
            if (m_.animations[a].name == at.animation)
                chosen.push_back(a);
        size_t index;
        if (chosen.empty() && parse_index(at.animation, &index) && index < n)
            chosen.push_back(index);
        if (chosen.empty())
            fail("%s does not exist: the file has %s", asked.c_str(), describe_animations(m_).c_str());
    }

    std::vector<lpv_gltf_node_override> out;
    for (size_t a : chosen) {
        Animation anim;
        read_animation(a, anim);
        ctx_.played.push_back(int(a));
        for (const Animation::Channel &c : anim.channels) {
            const Keys &k = anim.samplers[size_t(c.sampler)];
            if (c.path == Path::weights) {
                std::vector<double> w(size_t(k.ncomp));
                sample(k, at.time, false, w.data());
                weights.push_back({c.node, w});
                continue;
            }
            double v[4];
            sample(k, at.time, c.path == Path::rotation, v);
            lpv_gltf_node_override o;
            memset(&o, 0, sizeof o);
            o.node = c.node;
            if (c.path == Path::translation) {
                o.has_translation = 1;
                for (int i = 0; i < 3; i++)
                    o.translation[i] = float(v[i]);
            } else if (c.path == Path::rotation) {
                o.has_rotation = 1;
                for (int i = 0; i < 4; i++)
                    o.rotation[i] = float(v[i]);
            } else {
                o.has_scale = 1;
                for (int i = 0; i < 3; i++)
                    o.scale[i] = float(v[i]);
            }
            out.push_back(o);
        }
    }
    return out;
}

void Builder::list_animations(lpv_gltf_animation_list &out)
{
    memset(&out, 0, sizeof out);
    const size_t n = m_.animations.size();
    out.count = int(std::min(n, size_t(INT32_MAX)));
    for (size_t a = 0; a < n; a++) {
        Animation anim;
        read_animation(a, anim);
        if (a >= LPV_GLTF_ANIMATIONS_MAX)
            continue;
        lpv_gltf_animation_info &info = out.animation[a];
        copy_clean(info.name, sizeof info.name, m_.animations[a].name);
        info.duration = anim.duration;
        info.channels = int(anim.channels.size());
    }
}

} // namespace lpv_gltf
