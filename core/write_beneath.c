/*
 * write_beneath.c - write_beneath.h: folders opened one at a time with
 * O_NOFOLLOW from the output folder's descriptor, files made with O_EXCL and
 * renamed into place by descriptor, so no name inside the output folder is
 * resolved through a link.
 */
#define _GNU_SOURCE
#include "write_beneath.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "open_beneath.h"

int lpv_dir_make_beneath(int dirfd, const char *rel)
{
    if (lpv_path_stays_beneath(rel) != 0)
        return -1;
    int fd = fcntl(dirfd, F_DUPFD_CLOEXEC, 0);
    for (const char *q = rel; fd >= 0 && *q;) {
        size_t len = strcspn(q, "/");
        char comp[NAME_MAX + 1];
        if (len > NAME_MAX) {
            close(fd);
            errno = ENAMETOOLONG;
            return -1;
        }
        memcpy(comp, q, len);
        comp[len] = '\0';
        q += len;
        while (*q == '/')
            q++;
        if (len == 0 || strcmp(comp, ".") == 0)
            continue;
        if (mkdirat(fd, comp, 0777) != 0 && errno != EEXIST) {
            const int e = errno;
            close(fd);
            errno = e;
            return -1;
        }
        const int next = openat(fd, comp, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
        const int e = errno;
        close(fd);
        errno = e;
        fd = next;
    }
    return fd;
}

int lpv_fd_path(int dirfd, const char *name, char *out, size_t out_size)
{
    const int len = snprintf(out, out_size, "/proc/self/fd/%d/%s", dirfd, name);
    return len < 0 || (size_t)len >= out_size ? -1 : 0;
}

/* rel's folder (a copy, "" when none) and its last name. */
static int split(const char *rel, char folder[PATH_MAX], const char **name)
{
    const char *slash = strrchr(rel, '/');
    *name = slash ? slash + 1 : rel;
    const size_t len = slash ? (size_t)(slash - rel) : 0;
    if (len >= PATH_MAX || !**name || strcmp(*name, ".") == 0 || strcmp(*name, "..") == 0) {
        errno = EINVAL;
        return -1;
    }
    memcpy(folder, rel, len);
    folder[len] = '\0';
    return 0;
}

int lpv_write_beneath(int dirfd, const char *rel, lpv_path_writer fn, void *arg, char *err, size_t err_size)
{
    char folder[PATH_MAX], tmp[NAME_MAX + 1], path[PATH_MAX + 64];
    const char *name;
    if (split(rel, folder, &name) != 0 || lpv_path_stays_beneath(rel) != 0) {
        snprintf(err, err_size, "%s: not a file name beneath the output folder", rel);
        return -1;
    }
    const int fd = lpv_dir_make_beneath(dirfd, folder);
    if (fd < 0) {
        snprintf(err, err_size, "%s: %s%s", folder, strerror(errno),
                 errno == ELOOP || errno == ENOTDIR ? " (a symbolic link or a file where a folder belongs; "
                                                      "outputs are never written through one)"
                                                    : "");
        return -1;
    }
    const char *ext = strrchr(name, '.');
    if (!ext || ext == name)
        ext = name + strlen(name);
    const int len = snprintf(tmp, sizeof tmp, "%.*s.tmp-%ld%s", (int)(ext - name), name, (long)getpid(), ext);
    int rc = -1;
    if (len < 0 || (size_t)len >= sizeof tmp || lpv_fd_path(fd, tmp, path, sizeof path) != 0) {
        snprintf(err, err_size, "%s: name too long", rel);
        goto done;
    }
    int made = -1;
    for (int attempt = 0; attempt < 2 && made < 0; ++attempt) {
        made = openat(fd, tmp, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
        if (made < 0 && errno == EEXIST) /* this process's own leftover (a write that failed half way) */
            unlinkat(fd, tmp, 0);
    }
    if (made < 0) {
        snprintf(err, err_size, "%s: %s", rel, strerror(errno));
        goto done;
    }
    close(made);
    if (fn(path, arg, err, err_size) != 0) {
        unlinkat(fd, tmp, 0);
        goto done;
    }
    if (renameat(fd, tmp, fd, name) != 0) {
        const int e = errno;
        unlinkat(fd, tmp, 0);
        snprintf(err, err_size, "%s: %s", rel, strerror(e));
        goto done;
    }
    rc = 0;
done:
    close(fd);
    return rc;
}

int lpv_open_append_beneath(int dirfd, const char *rel)
{
    char folder[PATH_MAX];
    const char *name;
    if (split(rel, folder, &name) != 0)
        return -1;
    const int dir = lpv_dir_make_beneath(dirfd, folder);
    if (dir < 0)
        return -1;
    /* O_NONBLOCK: a FIFO put there must not block the open */
    const int fd = openat(dir, name, O_RDWR | O_APPEND | O_CREAT | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC, 0666);
    int e = errno;
    close(dir);
    if (fd < 0) {
        errno = e;
        return -1;
    }
    struct stat st;
    if (fstat(fd, &st) != 0)
        e = errno;
    else if (!S_ISREG(st.st_mode))
        e = EINVAL; /* a FIFO, a device, a socket */
    else if (fcntl(fd, F_SETFL, O_APPEND) != 0) /* blocking again */
        e = errno;
    else
        return fd;
    close(fd);
    errno = e;
    return -1;
}
