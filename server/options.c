/* options.c - see options.h. */
#include "options.h"

#include <stdio.h>
#include <string.h>

static const lpv_flag BACKEND_FLAGS[] = {
    {"backend", 0, "NAME", "auto | egl-device | egl-surfaceless | osmesa\n"
                           "(default auto; or the LPVD_GL_BACKEND variable)"},
};

static int parse_backend(void *target, const lpv_flag *f, const char *v, char *err, size_t n)
{
    (void)f;
    if (lpv_backend_parse(v ? v : "", target) != 0) {
        snprintf(err, n, "--backend %s: expected auto, egl-device, egl-surfaceless or osmesa", v ? v : "");
        return -1;
    }
    return 0;
}

int lpvd_options_groups(lpvd_options *o, int which, int handled, lpv_flag_group *out)
{
    int n = 0;
    if (which & LPVD_GROUP_SETTINGS)
        out[n++] = lpv_settings_flag_group(&o->settings);
    if (which & LPVD_GROUP_BACKEND)
        out[n++] = (lpv_flag_group){BACKEND_FLAGS, 1, parse_backend, &o->backend};
    if (which & LPVD_GROUP_CAMERA)
        out[n++] = lpv_view_flag_group(&o->cam);
    if (!handled)
        for (int i = 0; i < n; ++i)
            out[i].parse = NULL;
    return n;
}

int lpvd_option_parse(lpvd_options *o, const char *name, const char *v, char *err, size_t n)
{
    int r = lpv_settings_flag_parse(&o->settings, name, v, err, n);
    if (r == 0)
        r = lpv_view_flag_parse(&o->cam, name, v, err, n);
    if (r == 0 && strcmp(name, BACKEND_FLAGS[0].name) == 0)
        r = parse_backend(&o->backend, &BACKEND_FLAGS[0], v, err, n) == 0 ? 1 : -1;
    return r;
}

int lpvd_option_takes_value(const char *name)
{
    lpvd_options o;
    lpv_flag_group g[3];
    int ng = lpvd_options_groups(&o, LPVD_GROUP_ALL, 0, g);
    for (int i = 0; i < ng; ++i) {
        const lpv_flag *f = lpv_flag_find(g[i].flags, g[i].count, name);
        if (f)
            return f->metavar ? 1 : 0;
    }
    return -1;
}

const char *lpvd_options_help(void)
{
    static char help[20480];
    if (!help[0]) {
        size_t len = 0;
        lpv_flags_append(help, sizeof help, &len, "%sGL:\n", lpv_settings_flags_help());
        lpv_flags_help(help, sizeof help, &len, BACKEND_FLAGS, 1);
        lpv_flags_append(help, sizeof help, &len, "%s", lpv_view_flags_help());
    }
    return help;
}
