/* knob_rows.c - see knob_rows.h. */
#include "knob_rows.h"

#include <stdio.h>
#include <string.h>

#include "settings.h"

/* The sweep's short names since the first sweep (docs/accuracy.md); every
 * other sweepable knob goes by its row's key (iv_resolution, ...). */
static const struct {
    const char *alias, *key;
} ALIASES[] = {
    {"iterations", "iterations"},
    {"rsm", "rsm_size"},
    {"occlusion", "occlusion"},
    {"central", "central_transport"},
    {"bins", "normal_bins"},
    {"far", "far_field"},
    {"surfels", "scene_surfels"},
    {"camera_step", "camera_surfel_step"},
    {"rsm_step", "rsm_vpl_step"},
    {"lookup_step", "lookup_step"},
};
#define N_ALIASES (sizeof ALIASES / sizeof ALIASES[0])

const lpv_field *acc_knob_row(const char *name)
{
    if (!name)
        return NULL;
    for (size_t i = 0; i < N_ALIASES; ++i)
        if (strcmp(name, ALIASES[i].alias) == 0)
            return lpv_field_by_key(ALIASES[i].key);
    return lpv_field_by_key(name);
}

const char *acc_knob_alias(const char *key)
{
    for (size_t i = 0; i < N_ALIASES; ++i)
        if (strcmp(key, ALIASES[i].key) == 0)
            return ALIASES[i].alias;
    return key;
}

int acc_knob_value(const lpv_field *f, const char *tok, double *out, char *err, size_t err_size)
{
    if (!f || !tok)
        return -1;
    if (f->dflt_rule == LPV_DEFAULT_ZERO && f->dflt_words && strcmp(tok, f->dflt_words) == 0) {
        *out = 0.0; /* "auto": zero is the row's own word for it */
        return 0;
    }
    lpv_settings scratch;
    memset(&scratch, 0, sizeof scratch);
    char why[160];
    if (lpv_field_set_string(&scratch, f, tok, why, sizeof why) != 0) {
        if (err && err_size)
            snprintf(err, err_size, "%s: '%s': %s", f->key, tok, why);
        return -1;
    }
    *out = lpv_field_get(&scratch, f);
    return 0;
}

void acc_knob_rows_help(char *buf, size_t n)
{
    size_t at = 0;
    buf[0] = '\0';
    for (size_t i = 0; i < N_ALIASES && at < n; ++i) {
        const lpv_field *f = lpv_field_by_key(ALIASES[i].key);
        char want[96];
        const char *colon = strchr(f->note, ':'); /* "0 = auto: ..." -> "0 = auto" */
        const int note_len = colon ? (int)(colon - f->note) : (int)strlen(f->note);
        int w = snprintf(buf + at, n - at, "  %-12s = %s: %s%s%.*s\n", ALIASES[i].alias, f->key,
                         lpv_field_expect(f, want, sizeof want), note_len ? "; " : "", note_len, f->note);
        if (w < 0)
            break;
        at += (size_t)w;
    }
}
