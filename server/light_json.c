/* light_json.c - see light_json.h. */
#include "light_json.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "proto.h"

int lpvd_light_from_json(const json_t *j, lpv_light *out, char *err, size_t n)
{
    static const char *const TYPES[] = {"directional", "point", "spot"}; /* = lpv_light_type */
    const char *id = NULL;
    size_t idlen = 0;
    int type = 0;
    lpv_light l;
    memset(&l, 0, sizeof l);
    l.color[0] = l.color[1] = l.color[2] = 1.0f;
    l.direction[1] = -1.0f;
    l.outer_cone = (float)(M_PI / 4.0);
    if (lpvp_get_string(j, "id", 1, LPV_NAME_MAX - 1, &id, &idlen, err, n) != LPVP_FIELD_OK ||
        lpvp_get_enum(j, "type", 1, TYPES, 3, &type, err, n) != LPVP_FIELD_OK ||
        lpvp_get_floats(j, "color", 0, 3, 0.0, 1e30, l.color, err, n) == LPVP_FIELD_BAD ||
        lpvp_get_float(j, "intensity", 1, 0.0, 1e30, &l.intensity, err, n) != LPVP_FIELD_OK ||
        lpvp_get_floats(j, "position", 0, 3, -LPV_MAX_COORD, LPV_MAX_COORD, l.position, err, n) == LPVP_FIELD_BAD ||
        lpvp_get_floats(j, "direction", 0, 3, -1e30, 1e30, l.direction, err, n) == LPVP_FIELD_BAD ||
        lpvp_get_float(j, "range", 0, 0.0, LPV_MAX_COORD, &l.range, err, n) == LPVP_FIELD_BAD ||
        lpvp_get_float(j, "inner_cone", 0, 0.0, M_PI / 2.0, &l.inner_cone, err, n) == LPVP_FIELD_BAD ||
        lpvp_get_float(j, "outer_cone", 0, 0.0, M_PI / 2.0, &l.outer_cone, err, n) == LPVP_FIELD_BAD)
        return -1;
    if (idlen == 0) {
        snprintf(err, n, "id: must not be empty");
        return -1;
    }
    /* in double: components up to 1e30 square beyond float */
    double dl = sqrt((double)l.direction[0] * l.direction[0] + (double)l.direction[1] * l.direction[1] +
                     (double)l.direction[2] * l.direction[2]);
    if (!(dl > 1e-12)) {
        snprintf(err, n, "direction: must be a non-zero vector");
        return -1;
    }
    for (int i = 0; i < 3; ++i)
        l.direction[i] = (float)(l.direction[i] / dl);
    if (type == LPV_LIGHT_SPOT && l.inner_cone > l.outer_cone) {
        snprintf(err, n, "inner_cone: must not exceed outer_cone");
        return -1;
    }
    if (type != LPV_LIGHT_SPOT)
        l.inner_cone = l.outer_cone = 0.0f;
    l.type = (lpv_light_type)type;
    char why[256];
    if (lpv_light_check_intensity(&l, why, sizeof why) != 0) { /* 1e30 x 1e30 overflowed and lit nothing */
        snprintf(err, n, "intensity: %s", why);
        return -1;
    }
    memcpy(l.name, id, idlen);
    *out = l;
    return 0;
}
