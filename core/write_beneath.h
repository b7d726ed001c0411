/*
 * write_beneath.h - files written beneath an output folder that never go
 * through a symbolic link (`lpvd batch --out`, its report). The folder itself
 * is the user's to name (a link there is followed once, when it is opened);
 * inside it, a folder or file that is a link is refused or replaced, never
 * followed: a linked `thumbs/` or item folder is refused, and a link in place
 * of an output, a manifest or `contact.png` is replaced by the new file
 * instead of overwriting the link's target.
 */
#ifndef LPV_WRITE_BENEATH_H
#define LPV_WRITE_BENEATH_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The folder rel beneath dirfd ("" or "." for dirfd itself), each missing
 * folder on the way created (mode 0777 less the umask), each one opened with
 * O_NOFOLLOW (core/open_beneath.h). Returns a descriptor (O_DIRECTORY,
 * close it), or -1 with errno: ELOOP for a link on the way, EXDEV for an
 * absolute path or "..", ENOTDIR, EACCES, ... */
int lpv_dir_make_beneath(int dirfd, const char *rel);

/* A name by which a library that takes paths reaches name inside the
 * folder dirfd without resolving the folder's own path again:
 * /proc/self/fd/DIRFD/NAME. Returns 0, or -1 when it does not fit. */
int lpv_fd_path(int dirfd, const char *name, char *out, size_t out_size);

/* Writes a file by a function that takes a path (an image library's). */
typedef int (*lpv_path_writer)(const char *path, void *arg, char *err, size_t err_size);

/* Writes rel (folders created as lpv_dir_make_beneath does) beneath dirfd
 * atomically and without following a link: a fresh temporary file is made
 * beside it (O_CREAT | O_EXCL: never a link, never another's file), named
 * "<stem>.tmp-<pid><ext>" so a reader that globs by extension can tell it,
 * fn writes it through lpv_fd_path, and it is renamed over rel's name (a link
 * there is replaced, not followed). On failure nothing is left and err names
 * rel. Returns 0 or -1. */
int lpv_write_beneath(int dirfd, const char *rel, lpv_path_writer fn, void *arg, char *err, size_t err_size);

/* Opens rel beneath dirfd for appending (created, mode 0666 less the umask,
 * when missing), refusing a link or anything but a regular file: ELOOP,
 * EINVAL (not a regular file). Returns a descriptor or -1 with errno. */
int lpv_open_append_beneath(int dirfd, const char *rel);

#ifdef __cplusplus
}
#endif

#endif
