/* points_csv.h - the points file lpvd's tools read irradiance at: one point
 * per line, px,py,pz,nx,ny,nz (m; the normal need not be unit). `lpvctl query
 * --csv` and lpvd batch's points output read it here. */
#ifndef LPV_POINTS_CSV_H
#define LPV_POINTS_CSV_H

#include <stddef.h>
#include <stdio.h>

enum { LPV_POINTS_BAD_LINE = -2, LPV_POINTS_NO_MEMORY = -1 };

/* Reads f to its end: numbers separated by commas, semicolons or blanks;
 * blank lines are skipped, and so is a first line that is not numbers (a
 * header). *pts and *nrm get 3 floats per point (malloc'ed, free() them;
 * NULL on failure). Returns the number of points, or LPV_POINTS_BAD_LINE
 * with "LABEL:LINE: expected 6 numbers px,py,pz,nx,ny,nz" in err, or
 * LPV_POINTS_NO_MEMORY. */
long lpv_points_csv_read(FILE *f, const char *label, float **pts, float **nrm, char *err, size_t err_size);

#endif
