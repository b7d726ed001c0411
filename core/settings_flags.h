/*
 * settings_flags.h - the command-line face of lpv_settings: --preset, --grid,
 * --bounds and one flag per knob of the field table (settings_fields.h), as a
 * flag group for flags.h, with their help. Every lpvd command that runs the
 * engine takes them; the flag names live only in the field table.
 */
#ifndef LPV_SETTINGS_FLAGS_H
#define LPV_SETTINGS_FLAGS_H

#include <stddef.h>

#include "flags.h"
#include "settings.h"

/* The flags: preset, grid, bounds, then the field table's in its order. */
const lpv_flag *lpv_settings_flags(size_t *count);

/* Parses one settings flag (name without dashes) into s. Returns 1 if it was
 * one, 0 if not, -1 on a bad value ("--NAME VALUE: expected ..." in err).
 * Only --preset's name is recorded: resolving fills the fields no other flag
 * set, so --grid and the knobs win over --preset in any order. */
int lpv_settings_flag_parse(lpv_settings *s, const char *name, const char *value, char *err, size_t err_size);

/* The group for lpv_flags_begin, parsing into *s. */
lpv_flag_group lpv_settings_flag_group(lpv_settings *s);

/* The help for the settings flags: the presets from the preset table, the
 * knobs with range, unit and default from the field table. Built once. */
const char *lpv_settings_flags_help(void);

#endif /* LPV_SETTINGS_FLAGS_H */
