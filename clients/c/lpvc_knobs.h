/*
 * lpvc_knobs.h - internal to the C client: the daemon's description of its
 * settings knobs (SPEC R4.12) read from a HELLO reply, and CONFIG bodies
 * built against it. No I/O; the connection (lpvc_internal.h)
 * keeps one lpvc_knobset.
 */
#ifndef LPVC_KNOBS_H
#define LPVC_KNOBS_H

#include <jansson.h>

#include "lpvc.h"

typedef struct lpvc_knobset {
    json_t *hello;          /* the HELLO reply: the strings below point into it */
    lpvc_knob *knobs;
    size_t count;
    const char **presets;
    size_t preset_count;
    const char **techniques;
    size_t technique_count;
} lpvc_knobset;

/* Reads hello's "knobs", "presets" and "techniques" (absent: none) into *ks, keeping a
 * reference to hello. Returns 0, or -1 with a message in err when the
 * description breaks R4.12 (a knob without a name or type, a range that is
 * not numbers). */
int lpvc_knobset_read(lpvc_knobset *ks, json_t *hello, char *err, size_t n);
void lpvc_knobset_free(lpvc_knobset *ks);
const lpvc_knob *lpvc_knobset_find(const lpvc_knobset *ks, const char *name);

/* Adds each setting to the CONFIG body o, typed by its knob; -1 with
 * "<name>: <why>" in err for an unknown knob or a value it does not allow. */
int lpvc_knobset_add(const lpvc_knobset *ks, json_t *o, const lpvc_setting *set, size_t count, char *err, size_t n);

#endif
