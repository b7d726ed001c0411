/*
 * open_beneath.c - open_beneath.h: openat2 where the kernel has it (Linux
 * 5.6+), else a walk one component at a time from the folder's descriptor.
 */
#define _GNU_SOURCE
#include "open_beneath.h"

#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#ifdef __linux__
#include <linux/openat2.h>
#endif

#define ALWAYS_FLAGS (O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK)

int lpv_path_stays_beneath(const char *rel)
{
    if (!rel || rel[0] == '/') {
        errno = EXDEV;
        return -1;
    }
    for (const char *q = rel; *q;) {
        size_t len = strcspn(q, "/");
        if (len == 2 && q[0] == '.' && q[1] == '.') {
            errno = EXDEV;
            return -1;
        }
        q += len;
        while (*q == '/')
            q++;
    }
    return 0;
}

int lpv_open_beneath_walk(int dirfd, const char *rel, int flags)
{
    if (lpv_path_stays_beneath(rel) != 0)
        return -1;
    int cur = dirfd; /* never closed: the caller's */
    const char *q = rel;
    for (;;) {
        while (*q == '/')
            q++;
        size_t len = strcspn(q, "/");
        const char *rest = q + len;
        while (*rest == '/')
            rest++;
        int last = *rest == '\0';
        char comp[256];
        if (len >= sizeof comp) {
            errno = ENAMETOOLONG;
            goto fail;
        }
        memcpy(comp, q, len);
        comp[len] = '\0';
        if (len == 0)
            strcpy(comp, "."); /* "" or a trailing "/": the folder itself */
        int fd = last ? openat(cur, comp, flags | ALWAYS_FLAGS)
                      : (len == 1 && comp[0] == '.')
                            ? dup(cur)
                            : openat(cur, comp, O_RDONLY | O_DIRECTORY | ALWAYS_FLAGS);
        struct stat st;
        if (fd < 0 && errno == ENOTDIR && !last && fstatat(cur, comp, &st, AT_SYMLINK_NOFOLLOW) == 0 &&
            S_ISLNK(st.st_mode))
            errno = ELOOP; /* O_DIRECTORY | O_NOFOLLOW says ENOTDIR for a link: say what openat2 says */
        if (fd < 0)
            goto fail;
        if (cur != dirfd)
            close(cur);
        cur = fd;
        if (last)
            return cur;
        q = rest;
    }
fail:
    if (cur != dirfd) {
        int e = errno;
        close(cur);
        errno = e;
    }
    return -1;
}

int lpv_open_beneath(int dirfd, const char *rel, int flags)
{
#if defined(__linux__) && defined(SYS_openat2) && defined(RESOLVE_BENEATH)
    static int no_openat2; /* set once on ENOSYS; a benign race between threads */
    if (!no_openat2) {
        if (lpv_path_stays_beneath(rel) != 0)
            return -1;
        struct open_how how;
        memset(&how, 0, sizeof how);
        how.flags = (uint64_t)(flags | ALWAYS_FLAGS);
        how.resolve = RESOLVE_BENEATH | RESOLVE_NO_SYMLINKS;
        for (int tries = 0; tries < 16; ++tries) {
            long fd = syscall(SYS_openat2, dirfd, rel[0] ? rel : ".", &how, sizeof how);
            if (fd >= 0)
                return (int)fd;
            /* EAGAIN: a rename raced the lookup (the kernel asks for a retry) */
            if (errno != EAGAIN && errno != EINTR)
                break;
        }
        if (errno != ENOSYS)
            return -1;
        no_openat2 = 1;
    }
#endif
    return lpv_open_beneath_walk(dirfd, rel, flags);
}
