/*
 * gltf_lights_cameras.cpp - the Builder's KHR_lights_punctual lights
 * (directional, point, spot with cone angles and range; candela and lux to
 * W/sr and W/m^2, docs/units.md) and cameras (perspective, orthographic),
 * placed by their node's world transform (gltf_internal.hpp).
 */
#include "gltf_internal.hpp"

#include <cmath>
#include <cstring>

namespace lpv_gltf {

void Builder::add_light(int node, int li, const Mat4 &world)
{
    if (li < 0 || size_t(li) >= m_.lights.size())
        fail("node %d: KHR_lights_punctual light %d does not exist (out of range)", node, li);
    const tinygltf::Light &gl = m_.lights[size_t(li)];
    lpv_light l;
    memset(&l, 0, sizeof l);
    if (gl.type == "directional")
        l.type = LPV_LIGHT_DIRECTIONAL;
    else if (gl.type == "point")
        l.type = LPV_LIGHT_POINT;
    else if (gl.type == "spot")
        l.type = LPV_LIGHT_SPOT;
    else {
        ctx_.warn(strf("light %d has unknown type %s; skipped", li, show(gl.type).c_str()));
        return;
    }
    copy_name(l.name, gl.name, strf("light%zu", lights.size()));
    l.color[0] = l.color[1] = l.color[2] = 1.0f;
    if (!gl.color.empty()) {
        if (gl.color.size() != 3 || !finite_all(gl.color))
            fail("light %d: color must hold 3 finite numbers", li);
        for (int k = 0; k < 3; k++)
            l.color[k] = float(gl.color[size_t(k)]);
    }
    if (!std::isfinite(gl.intensity) || gl.intensity < 0.0)
        fail("light %d: intensity must be a finite number >= 0", li);
    /* cd -> W/sr (point, spot) and lx -> W/m^2 (directional): docs/units.md */
    l.intensity = float(gl.intensity / double(LPV_LUMENS_PER_WATT));
    l.range = (std::isfinite(gl.range) && gl.range > 0.0) ? float(gl.range) : 0.0f;
    if (l.type == LPV_LIGHT_SPOT) {
        if (!std::isfinite(gl.spot.innerConeAngle) || !std::isfinite(gl.spot.outerConeAngle))
            fail("light %d: spot cone angles must be finite", li);
        l.inner_cone = float(gl.spot.innerConeAngle);
        l.outer_cone = float(gl.spot.outerConeAngle);
    }
    double origin[3] = {0, 0, 0}, pos[3], down[3] = {0, 0, -1}, dir[3];
    xform_point(world, origin, pos);
    xform_dir(world, down, dir);
    if (!normalize3(dir)) {
        dir[0] = 0;
        dir[1] = 0;
        dir[2] = -1;
    }
    for (int k = 0; k < 3; k++) {
        l.position[k] = float(pos[k]);
        l.direction[k] = float(dir[k]);
    }
    lights.push_back(l);
}

void Builder::add_camera(int node, int ci, const Mat4 &world)
{
    if (ci < 0 || size_t(ci) >= m_.cameras.size())
        fail("node %d: camera %d does not exist (out of range)", node, ci);
    const tinygltf::Camera &gc = m_.cameras[size_t(ci)];
    lpv_camera c;
    memset(&c, 0, sizeof c);
    if (gc.type == "perspective") {
        c.orthographic = 0;
        c.yfov = float(gc.perspective.yfov);
        c.aspect = float(gc.perspective.aspectRatio);
        c.znear = float(gc.perspective.znear);
        c.zfar = float(gc.perspective.zfar);
    } else if (gc.type == "orthographic") {
        c.orthographic = 1;
        c.xmag = float(gc.orthographic.xmag);
        c.ymag = float(gc.orthographic.ymag);
        c.znear = float(gc.orthographic.znear);
        c.zfar = float(gc.orthographic.zfar);
    } else {
        ctx_.warn(strf("camera %d has unknown type %s; skipped", ci, show(gc.type).c_str()));
        return;
    }
    copy_name(c.name, gc.name, strf("camera%zu", cameras.size()));
    double origin[3] = {0, 0, 0}, eye[3], fwd_l[3] = {0, 0, -1}, up_l[3] = {0, 1, 0}, fwd[3], up[3];
    xform_point(world, origin, eye);
    xform_dir(world, fwd_l, fwd);
    xform_dir(world, up_l, up);
    if (!normalize3(fwd))
        fwd[0] = 0, fwd[1] = 0, fwd[2] = -1;
    if (!normalize3(up))
        up[0] = 0, up[1] = 1, up[2] = 0;
    for (int k = 0; k < 3; k++) {
        c.eye[k] = float(eye[k]);
        c.forward[k] = float(fwd[k]);
        c.up[k] = float(up[k]);
    }
    cameras.push_back(c);
}

} // namespace lpv_gltf
