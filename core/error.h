/* error.h - the one way lpvd's C code reports a failure: a message written
 * into a caller-supplied buffer (err, err_size), and -1 returned. */
#ifndef LPV_ERROR_H
#define LPV_ERROR_H

#include <stddef.h>

/* The longest message lpv_error writes (bytes with the terminator); longer
 * ones are cut. */
#define LPV_ERROR_MAX 4096

/* printf-formats into err (if err and err_size are non-zero); returns -1 so
 * callers can write "return lpv_error(err, n, ...);". An argument may point
 * into err itself: "lpv_error(err, n, \"%s: %s\", source, err)" prefixes the
 * message a callee left there. */
int lpv_error(char *err, size_t err_size, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

#endif
