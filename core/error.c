/* error.c - see error.h. */
#include "error.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

int lpv_error(char *err, size_t err_size, const char *fmt, ...)
{
    if (err && err_size) {
        /* formatted aside first: the arguments may point into err itself (a
         * caller prefixing its callee's message, "%s: %s", source, err), and
         * vsnprintf's source and destination must not overlap */
        char tmp[LPV_ERROR_MAX];
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(tmp, err_size < sizeof tmp ? err_size : sizeof tmp, fmt, ap);
        va_end(ap);
        size_t n = strlen(tmp);
        if (n >= err_size)
            n = err_size - 1;
        memcpy(err, tmp, n);
        err[n] = '\0';
    }
    return -1;
}
