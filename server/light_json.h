/* light_json.h - a light described in JSON (SPEC R4.6's LIGHT_SET body: id,
 * type, colour, intensity, position, direction, range, cones), read in one
 * place for the daemon's LIGHT_SET and lpvd batch's job files. */
#ifndef LPVD_LIGHT_JSON_H
#define LPVD_LIGHT_JSON_H

#include <stddef.h>

#include <jansson.h>

#include "scene.h"

/* Fills *out from j: "id" (the light's name, non-empty) and "type"
 * (directional | point | spot) and "intensity" required; colour defaults to
 * white, direction to -Y (normalised here), cones to 0 and 45 degrees (spot
 * only). Returns 0, or -1 with a message naming the key in err. */
int lpvd_light_from_json(const json_t *j, lpv_light *out, char *err, size_t n);

#endif
