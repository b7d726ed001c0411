/*
 * gltf_medium.cpp - lpvd's participating medium from the file's extras
 * (gltf_internal.hpp; docs/scenes.md, "Media"), every field checked and named
 * when refused.
 */
#include "gltf_internal.hpp"

#include <cmath>
#include <cstring>
#include <initializer_list>
#include <limits>

#include <nlohmann/json.hpp>

namespace lpv_gltf {

namespace {

/* Read from the raw JSON with nlohmann rather than from tinygltf's Value,
 * which drops nulls from arrays and truncates large integers to int. Every
 * message names the field: "lpvd_medium.density.values[3]: ...". */
using Json = nlohmann::json;

/* A value from the file for a message, cut short. */
std::string brief(const Json &v)
{
    std::string d = v.dump(-1, ' ', false, Json::error_handler_t::replace);
    if (d.size() > 40)
        d = d.substr(0, 40) + "...";
    return d;
}

/* A finite number in [lo, hi], or a failure naming field. */
double medium_number(const Json &v, const std::string &field, double lo, double hi, const char *unit)
{
    if (!v.is_number())
        fail("%s: %s is not a number", field.c_str(), brief(v).c_str());
    double d = v.get<double>();
    if (!std::isfinite(d))
        fail("%s: %s is not finite", field.c_str(), brief(v).c_str());
    if (d < lo || d > hi)
        fail("%s: %g is out of range (must be %g .. %g%s)", field.c_str(), d, lo, hi, unit);
    return d;
}

void medium_rgb(const Json &m, const char *key, float out[3])
{
    const std::string field = std::string("lpvd_medium.") + key;
    auto it = m.find(key);
    if (it == m.end())
        fail("%s: missing (a number or [r,g,b] in 1/m; 0 for none)", field.c_str());
    const double hi = double(LPV_MEDIUM_SIGMA_MAX);
    if (it->is_number()) {
        float v = float(medium_number(*it, field, 0.0, hi, " 1/m"));
        out[0] = out[1] = out[2] = v;
        return;
    }
    if (!it->is_array())
        fail("%s: %s must be a number or an array [r,g,b] of numbers", field.c_str(), brief(*it).c_str());
    if (it->size() != 3)
        fail("%s: %zu values, [r,g,b] needs 3", field.c_str(), it->size());
    for (size_t k = 0; k < 3; k++)
        out[k] = float(medium_number((*it)[k], strf("%s[%zu]", field.c_str(), k), 0.0, hi, " 1/m"));
}

void medium_vec3(const Json &v, const std::string &field, float out[3])
{
    if (!v.is_array())
        fail("%s: %s must be an array [x,y,z] of numbers (m)", field.c_str(), brief(v).c_str());
    if (v.size() != 3)
        fail("%s: %zu values, [x,y,z] needs 3", field.c_str(), v.size());
    for (size_t k = 0; k < 3; k++) {
        const std::string f = strf("%s[%zu]", field.c_str(), k);
        const Json &c = v[k];
        if (!c.is_number())
            fail("%s: %s is not a number", f.c_str(), brief(c).c_str());
        const double d = c.get<double>();
        if (!std::isfinite(d) || std::fabs(d) > double(std::numeric_limits<float>::max()))
            fail("%s: %s is out of range (must be a finite float, m)", f.c_str(), brief(c).c_str());
        out[k] = float(d);
    }
}

void medium_unknown_keys(const Json &o, const char *field, std::initializer_list<const char *> known, Ctx &ctx)
{
    for (auto it = o.begin(); it != o.end(); ++it) {
        bool ok = false;
        for (const char *k : known)
            ok = ok || it.key() == k;
        if (!ok)
            ctx.warn(strf("%s.%s: unknown field, ignored", field, show(it.key()).c_str()));
    }
}

/* Parses and checks one lpvd_medium object into m (density into values). */
void parse_medium(const Json &j, lpv_medium &m, std::vector<float> &values, Ctx &ctx)
{
    memset(&m, 0, sizeof m);
    values.clear();
    if (!j.is_object())
        fail("lpvd_medium: %s must be an object {\"sigma_s\", \"sigma_a\", \"box\"?, \"density\"?}", brief(j).c_str());
    medium_unknown_keys(j, "lpvd_medium", {"sigma_s", "sigma_a", "box", "density"}, ctx);
    medium_rgb(j, "sigma_s", m.sigma_s);
    medium_rgb(j, "sigma_a", m.sigma_a);

    auto box = j.find("box");
    if (box != j.end()) {
        if (!box->is_object())
            fail("lpvd_medium.box: %s must be an object {\"min\":[x,y,z], \"max\":[x,y,z]}", brief(*box).c_str());
        medium_unknown_keys(*box, "lpvd_medium.box", {"min", "max"}, ctx);
        for (const char *k : {"min", "max"})
            if (!box->contains(k))
                fail("lpvd_medium.box.%s: missing ([x,y,z] in m)", k);
        medium_vec3((*box)["min"], "lpvd_medium.box.min", m.box_min);
        medium_vec3((*box)["max"], "lpvd_medium.box.max", m.box_max);
        static const char axis[] = "xyz";
        for (int k = 0; k < 3; k++)
            if (!(m.box_min[k] < m.box_max[k]))
                fail("lpvd_medium.box: min.%c %g is not below max.%c %g (the box must not be empty)", axis[k],
                     double(m.box_min[k]), axis[k], double(m.box_max[k]));
        m.has_box = 1;
    }

    auto den = j.find("density");
    if (den != j.end()) {
        if (!den->is_object())
            fail("lpvd_medium.density: %s must be an object {\"dims\":[nx,ny,nz], \"values\":[...]}",
                 brief(*den).c_str());
        if (!m.has_box)
            fail("lpvd_medium.density: needs a \"box\" to place it in (lpvd_medium.box is missing)");
        medium_unknown_keys(*den, "lpvd_medium.density", {"dims", "values"}, ctx);
        auto dims = den->find("dims");
        if (dims == den->end())
            fail("lpvd_medium.density.dims: missing ([nx,ny,nz], each 1 .. %d)", LPV_MEDIUM_DIMS_MAX);
        if (!dims->is_array() || dims->size() != 3)
            fail("lpvd_medium.density.dims: %s must be an array [nx,ny,nz] of 3 integers", brief(*dims).c_str());
        size_t count = 1;
        for (size_t k = 0; k < 3; k++) {
            const std::string f = strf("lpvd_medium.density.dims[%zu]", k);
            const Json &d = (*dims)[k];
            if (!d.is_number())
                fail("%s: %s is not a number", f.c_str(), brief(d).c_str());
            double v = d.get<double>();
            if (!(v >= 1.0 && v <= double(LPV_MEDIUM_DIMS_MAX)) || v != std::floor(v))
                fail("%s: %s must be an integer 1 .. %d", f.c_str(), brief(d).c_str(), LPV_MEDIUM_DIMS_MAX);
            m.dims[k] = int(v);
            count *= size_t(m.dims[k]);
        }
        auto vals = den->find("values");
        if (vals == den->end())
            fail("lpvd_medium.density.values: missing (%zu numbers for dims %dx%dx%d, x fastest)", count, m.dims[0],
                 m.dims[1], m.dims[2]);
        if (!vals->is_array())
            fail("lpvd_medium.density.values: %s must be an array of numbers", brief(*vals).c_str());
        if (vals->size() != count)
            fail("lpvd_medium.density.values: %zu values, dims %dx%dx%d need %zu", vals->size(), m.dims[0],
                 m.dims[1], m.dims[2], count);
        values.resize(count);
        for (size_t i = 0; i < count; i++) {
            const Json &v = (*vals)[i];
            if (!v.is_number())
                fail("lpvd_medium.density.values[%zu]: %s is not a number", i, brief(v).c_str());
            double d = v.get<double>();
            if (!std::isfinite(d) || d < 0.0 || d > double(LPV_MEDIUM_DENSITY_MAX))
                fail("lpvd_medium.density.values[%zu]: %s is out of range (must be finite, 0 .. %g)", i,
                     brief(v).c_str(), double(LPV_MEDIUM_DENSITY_MAX));
            values[i] = float(d);
        }
    }

    bool any = false;
    for (int k = 0; k < 3; k++)
        any = any || m.sigma_s[k] > 0.0f || m.sigma_a[k] > 0.0f;
    if (!any) { /* sigma_s = sigma_a = 0: no medium */
        memset(&m, 0, sizeof m);
        values.clear();
        return;
    }
    m.present = 1;
}

} // namespace

void read_medium(const char *json, size_t len, const tinygltf::Model &model, Ctx &ctx, lpv_medium &m,
                 std::vector<float> &values)
{
    memset(&m, 0, sizeof m);
    values.clear();
    static const char key[] = "lpvd_medium";
    if (!memmem(json, len, key, sizeof key - 1))
        return; /* the common case: no need to parse the JSON again */
    Json doc = Json::parse(json, json + len, nullptr, false);
    if (doc.is_discarded() || !doc.is_object())
        fail("invalid JSON while reading lpvd_medium");
    int scene = model.defaultScene;
    if (scene < 0 && !model.scenes.empty())
        scene = 0;
    const Json *found = nullptr;
    auto scenes = doc.find("scenes");
    if (scene >= 0 && scenes != doc.end() && scenes->is_array() && size_t(scene) < scenes->size()) {
        const Json &sc = (*scenes)[size_t(scene)];
        auto ex = sc.is_object() ? sc.find("extras") : sc.end();
        if (ex != sc.end() && ex->is_object() && ex->contains(key))
            found = &(*ex)[key];
    }
    auto ex = doc.find("extras");
    if (ex != doc.end() && ex->is_object() && ex->contains(key)) {
        if (found)
            ctx.warn(strf("both scene %d and the document carry extras.lpvd_medium; the scene's is used", scene));
        else
            found = &(*ex)[key];
    }
    if (found)
        parse_medium(*found, m, values, ctx);
}

} // namespace lpv_gltf
