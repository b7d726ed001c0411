/*
 * settings_rows.h - the macros a table of knob rows (lpv_field) is written
 * with: core's (settings_fields.c) and each technique's
 * (techniques/NAME/core/NAME_fields.c). Include it just before the table
 * and settings_rows_end.h just after.
 */
#include <stddef.h>

#include "settings_fields.h"

#define F(name) offsetof(lpv_settings, name)
/* The touches column (settings_fields.h, lpv_touch). */
#define T_VOL LPV_TOUCH_VOLUME
#define T_SAMPLES LPV_TOUCH_SAMPLES
#define T_SHADOWS LPV_TOUCH_SHADOWS
#define T_SHADE LPV_TOUCH_SHADING
/* The default columns (settings_fields.h, lpv_default_rule). */
#define D(value) LPV_DEFAULT_VALUE, (value), NULL
#define D_ZERO(words) LPV_DEFAULT_ZERO, 0, (words)
#define D_PRESET(words) LPV_DEFAULT_PRESET, 0, (words)
