/*
 * acc_files.c - folders for lpvd-accuracy's outputs (OUT/ref, OUT/err/SCENE,
 * OUT/plot), made with their parents; used by main, the scene run and the
 * plots, so in a file of its own.
 */
#include <errno.h>
#include <stdio.h>
#include <sys/stat.h>
#include <sys/types.h>

#include "accuracy_internal.h"

int acc_mkdir_p(const char *path)
{
    char buf[1024];
    snprintf(buf, sizeof buf, "%s", path);
    for (char *p = buf + 1; *p; ++p) {
        if (*p == '/') {
            *p = '\0';
            if (mkdir(buf, 0777) != 0 && errno != EEXIST)
                return -1;
            *p = '/';
        }
    }
    return (mkdir(buf, 0777) != 0 && errno != EEXIST) ? -1 : 0;
}
