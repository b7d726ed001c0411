/*
 * open_beneath.h - opening a file beneath a folder's descriptor with no window
 * between the check and the open (the daemon's --scene-root and a scene's
 * external URIs). A path that is absolute, has a ".." component or meets a
 * symbolic link anywhere on the way is refused by the same step that opens
 * it, so a file swapped for a link while it is being opened can never be
 * followed out of the folder.
 */
#ifndef LPV_OPEN_BENEATH_H
#define LPV_OPEN_BENEATH_H

#ifdef __cplusplus
extern "C" {
#endif

/* Opens rel (relative; "." and empty components are skipped) beneath dirfd.
 * flags are open(2) flags for the last component (O_RDONLY, O_DIRECTORY, ...);
 * O_CLOEXEC, O_NOFOLLOW and O_NONBLOCK (a FIFO must never block the caller)
 * are always added. Uses openat2(RESOLVE_BENEATH | RESOLVE_NO_SYMLINKS) where
 * the kernel has it, else lpv_open_beneath_walk. Returns the descriptor, or -1
 * with errno: EXDEV for an absolute path or a ".." component, ELOOP for a
 * symbolic link, ENOENT, ENOTDIR, EACCES, ... as open(2) says. */
int lpv_open_beneath(int dirfd, const char *rel, int flags);

/* The fallback, exported for its tests: one component at a time from dirfd,
 * each folder opened with O_DIRECTORY | O_NOFOLLOW, the last component with
 * O_NOFOLLOW; same contract as lpv_open_beneath. */
int lpv_open_beneath_walk(int dirfd, const char *rel, int flags);

/* The lexical part of both: 0 when rel is relative and has no ".."
 * component, else -1 with errno EXDEV. */
int lpv_path_stays_beneath(const char *rel);

#ifdef __cplusplus
}
#endif

#endif
