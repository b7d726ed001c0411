/*
 * knob_rows.h - the sweep's knobs are rows of lpvd's knob table
 * (core/settings_fields.c): a value in --knobs or --points is parsed and
 * range-checked by its row, so the sweep accepts exactly what a flag or
 * CONFIG accepts and says so in the row's words. The sweep's short names
 * (rsm, central, bins, ...) are aliases of the rows' keys, listed once here.
 * Plain C, no GL.
 */
#ifndef LPV_ACC_KNOB_ROWS_H
#define LPV_ACC_KNOB_ROWS_H

#include <stddef.h>

#include "settings_fields.h"

/* The row a --knobs name stands for: the sweep's alias ("rsm" ->
 * rsm_size) or a row's own key ("rsm_size"); NULL when neither. */
const lpv_field *acc_knob_row(const char *name);

/* The sweep's alias of the row with this key, or the key itself. */
const char *acc_knob_alias(const char *key);

/* One value of the row's knob: a number in the row's range, on/off for a
 * switch (1 / 0), or the row's zero word ("auto") where zero means that
 * (0). Returns 0, or -1 with err saying what the row expects. */
int acc_knob_value(const lpv_field *f, const char *tok, double *out, char *err, size_t err_size);

/* One line per alias for --help: "  rsm = rsm_size: an integer in 16..4096". */
void acc_knob_rows_help(char *buf, size_t n);

#endif
