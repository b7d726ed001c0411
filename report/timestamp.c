/* timestamp.c - RFC 3339 times to seconds since the epoch (timestamp.h). */
#include "timestamp.h"

#include <stddef.h>
#include <time.h>

/* n decimal digits at *p (advanced past them) into *v; 0, or -1 if a
 * character is not a digit. */
static int digits(const char **p, int n, int *v)
{
    int x = 0;
    for (int i = 0; i < n; i++) {
        char c = (*p)[i];
        if (c < '0' || c > '9')
            return -1;
        x = x * 10 + (c - '0');
    }
    *p += n;
    *v = x;
    return 0;
}

static int expect(const char **p, char a, char b)
{
    if (**p != a && **p != b)
        return -1;
    (*p)++;
    return 0;
}

int lpv_batch_time_parse(const char *text, double *s)
{
    if (!text || !s)
        return -1;
    const char *p = text;
    int year, mon, day, hour, min, sec;
    if (digits(&p, 4, &year) || expect(&p, '-', '-') || digits(&p, 2, &mon) || expect(&p, '-', '-') ||
        digits(&p, 2, &day) || expect(&p, 'T', 't') || digits(&p, 2, &hour) || expect(&p, ':', ':') ||
        digits(&p, 2, &min) || expect(&p, ':', ':') || digits(&p, 2, &sec))
        return -1;
    if (mon < 1 || mon > 12 || day < 1 || day > 31 || hour > 23 || min > 59 || sec > 60)
        return -1;
    double frac = 0.0;
    if (*p == '.') {
        p++;
        double scale = 0.1;
        if (*p < '0' || *p > '9')
            return -1;
        while (*p >= '0' && *p <= '9') {
            frac += scale * (*p - '0');
            scale *= 0.1;
            p++;
        }
    }
    int offset = 0; /* seconds east of UTC */
    if (*p == 'Z' || *p == 'z') {
        p++;
    } else if (*p == '+' || *p == '-') {
        int sign = *p == '-' ? -1 : 1, oh, om;
        p++;
        if (digits(&p, 2, &oh) || expect(&p, ':', ':') || digits(&p, 2, &om) || oh > 23 || om > 59)
            return -1;
        offset = sign * (oh * 3600 + om * 60);
    } else {
        return -1;
    }
    if (*p != '\0')
        return -1;
    struct tm tm = {0};
    tm.tm_year = year - 1900;
    tm.tm_mon = mon - 1;
    tm.tm_mday = day;
    tm.tm_hour = hour;
    tm.tm_min = min;
    tm.tm_sec = sec;
    time_t t = timegm(&tm);
    *s = (double)t - (double)offset + frac;
    return 0;
}
