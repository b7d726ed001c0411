/*
 * technique_fields.c - each technique's own knob rows
 * (techniques/NAME/core/NAME_fields.c), which the knob table
 * (core/settings_fields.c, lpv_fields) lists after core's, in this order.
 * A list apart from registry.c's rows: the knob table sits below the
 * registry's plan and tick-cost functions, which read settings, and these
 * rows depend on nothing but headers.
 */
#include "iv_rules.h"
#include "probes_rules.h"
#include "settings_fields.h"

typedef const lpv_field *(*rows_fn)(size_t *count);

static const rows_fn ROWS[] = {lpv_iv_fields, lpv_probes_fields};

const lpv_field *lpv_technique_fields(size_t k, size_t *count)
{
    *count = 0;
    return k < sizeof ROWS / sizeof ROWS[0] ? ROWS[k](count) : NULL;
}
