/* raycast.c - see raycast.h. */
#include "raycast.h"

#include <embree3/rtcore.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct lpv_raycast {
    RTCDevice device;
    RTCScene scene;
    unsigned count;
    float *front; /* 3 per triangle */
};

void lpv_raycast_destroy(lpv_raycast *rc)
{
    if (!rc)
        return;
    if (rc->scene)
        rtcReleaseScene(rc->scene);
    if (rc->device)
        rtcReleaseDevice(rc->device);
    free(rc->front);
    free(rc);
}

unsigned lpv_raycast_triangles(const lpv_raycast *rc)
{
    return rc ? rc->count : 0;
}

int lpv_raycast_create(const lpv_scene *s, lpv_raycast **out, char *err, size_t n)
{
    *out = NULL;
    lpv_raycast *rc = calloc(1, sizeof *rc);
    uint32_t cap = s->index_count / 3;
    float *pos = malloc(((size_t)cap * 9 + 3) * sizeof(float));
    if (!rc || !pos || !(rc->front = malloc(((size_t)cap * 3 + 1) * sizeof(float)))) {
        snprintf(err, n, "%s: out of memory for ray casting", s->source);
        free(pos);
        lpv_raycast_destroy(rc);
        return -1;
    }
    for (uint32_t d = 0; d < s->draw_count; ++d) {
        const lpv_draw *dr = &s->draws[d];
        for (uint32_t i = 0; i + 3 <= dr->index_count; i += 3) {
            const lpv_vertex *v[3];
            double area;
            if (!lpv_scene_triangle(s, dr->first_index + i, v, rc->front + 3 * (size_t)rc->count, &area))
                continue;
            for (int k = 0; k < 3; ++k)
                memcpy(pos + 9 * (size_t)rc->count + 3 * (size_t)k, v[k]->position, 3 * sizeof(float));
            rc->count++;
        }
    }
    rc->device = rtcNewDevice("threads=1");
    if (!rc->device) {
        snprintf(err, n, "%s: Embree: rtcNewDevice failed", s->source);
        free(pos);
        lpv_raycast_destroy(rc);
        return -1;
    }
    if (rc->count) {
        rc->scene = rtcNewScene(rc->device);
        RTCGeometry g = rtcNewGeometry(rc->device, RTC_GEOMETRY_TYPE_TRIANGLE);
        /* Embree reads vertex buffers 16 bytes at a time: one spare vertex. */
        float *vb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                            (size_t)rc->count * 3 + 1);
        unsigned *ib = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
                                               rc->count);
        if (vb && ib) {
            memcpy(vb, pos, (size_t)rc->count * 9 * sizeof(float));
            vb[9 * (size_t)rc->count] = vb[9 * (size_t)rc->count + 1] = vb[9 * (size_t)rc->count + 2] = 0.0f;
            for (unsigned t = 0; t < rc->count * 3; ++t)
                ib[t] = t;
            rtcCommitGeometry(g);
            rtcAttachGeometry(rc->scene, g);
        }
        rtcReleaseGeometry(g);
        rtcCommitScene(rc->scene);
        if (!vb || !ib || rtcGetDeviceError(rc->device) != RTC_ERROR_NONE) {
            snprintf(err, n, "%s: Embree: building the ray-casting structure failed", s->source);
            free(pos);
            lpv_raycast_destroy(rc);
            return -1;
        }
    }
    free(pos);
    *out = rc;
    return 0;
}

int lpv_raycast_hit(const lpv_raycast *rc, const float org[3], const float dir[3], float tmin, float tmax, float *t,
                    float front[3])
{
    if (!rc || !rc->scene)
        return 0;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    struct RTCRayHit rh;
    memset(&rh, 0, sizeof rh);
    rh.ray.org_x = org[0];
    rh.ray.org_y = org[1];
    rh.ray.org_z = org[2];
    rh.ray.dir_x = dir[0];
    rh.ray.dir_y = dir[1];
    rh.ray.dir_z = dir[2];
    rh.ray.tnear = tmin;
    rh.ray.tfar = tmax;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(rc->scene, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID || rh.hit.primID >= rc->count)
        return 0;
    if (t)
        *t = rh.ray.tfar;
    if (front)
        memcpy(front, rc->front + 3 * (size_t)rh.hit.primID, 3 * sizeof(float));
    return 1;
}
