/* settings_rows_end.h - undoes settings_rows.h after a table of rows. */
#undef F
#undef T_VOL
#undef T_SAMPLES
#undef T_SHADOWS
#undef T_SHADE
#undef D
#undef D_ZERO
#undef D_PRESET
