/*
 * timestamp.h - the manifests' times ("started", "finished") as numbers.
 */
#ifndef LPV_BATCH_TIMESTAMP_H
#define LPV_BATCH_TIMESTAMP_H

/* Parses an RFC 3339 time, "YYYY-MM-DDTHH:MM:SS" with an optional fraction
 * ".fff..." and a zone "Z", "+HH:MM" or "-HH:MM" (lower-case t and z too),
 * into seconds since 1970-01-01T00:00:00Z. Returns 0, or -1 (s untouched)
 * when the text is anything else. */
int lpv_batch_time_parse(const char *text, double *s);

#endif
