/* points_csv.c - see points_csv.h. */
#include "points_csv.h"

#include <stdlib.h>
#include <string.h>

#include "error.h"

/* Up to n numbers of line (modified) into out: how many, or -1 when a token
 * is not a number. */
static int csv_numbers(char *line, float *out, int n)
{
    int k = 0;
    char *save = NULL;
    for (char *tok = strtok_r(line, ",; \t\r\n", &save); tok && k < n; tok = strtok_r(NULL, ",; \t\r\n", &save)) {
        char *end;
        double v = strtod(tok, &end);
        if (end == tok || *end != '\0')
            return -1;
        out[k++] = (float)v;
    }
    return k;
}

long lpv_points_csv_read(FILE *f, const char *label, float **pts_out, float **nrm_out, char *err, size_t err_size)
{
    size_t n = 0, cap = 256, lineno = 0;
    float *pts = malloc(cap * 3 * sizeof(float)), *nrm = malloc(cap * 3 * sizeof(float));
    char line[4096];
    long rc = 0;
    while (pts && nrm && fgets(line, sizeof line, f)) {
        lineno++;
        float v[6];
        int k = csv_numbers(line, v, 6);
        if (k == 0)
            continue; /* blank line */
        if (k < 0 && n == 0 && lineno == 1)
            continue; /* header */
        if (k != 6) {
            lpv_error(err, err_size, "%s:%zu: expected 6 numbers px,py,pz,nx,ny,nz", label, lineno);
            rc = LPV_POINTS_BAD_LINE;
            break;
        }
        if (n == cap) {
            cap *= 2;
            float *p2 = realloc(pts, cap * 3 * sizeof(float));
            if (p2)
                pts = p2;
            float *n2 = realloc(nrm, cap * 3 * sizeof(float));
            if (n2)
                nrm = n2;
            if (!p2 || !n2) {
                rc = LPV_POINTS_NO_MEMORY;
                break;
            }
        }
        memcpy(pts + 3 * n, v, 3 * sizeof(float));
        memcpy(nrm + 3 * n, v + 3, 3 * sizeof(float));
        n++;
    }
    if (rc == 0 && (!pts || !nrm))
        rc = LPV_POINTS_NO_MEMORY;
    if (rc == LPV_POINTS_NO_MEMORY)
        lpv_error(err, err_size, "%s: out of memory after %zu points", label, n);
    if (rc != 0) {
        free(pts);
        free(nrm);
        pts = nrm = NULL;
    }
    *pts_out = pts;
    *nrm_out = nrm;
    return rc != 0 ? rc : (long)n;
}
