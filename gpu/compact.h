/*
 * compact.h - the RSMs' VPLs that carry light copied densely, in order, with
 * their count as a draw command (shaders/compact.comp, compact.glsl), so that
 * the injection draws only them (lpv_atlas_splat_indirect): the producers
 * mark each live VPL's bit, the scan turns the bits into places, the copy
 * moves the VPLs there.
 */
#ifndef LPV_COMPACT_H
#define LPV_COMPACT_H

#include <stddef.h>

#include "gl.h"

/* Bytes of the head buffer for `count` samples: the draw command, then per
 * chunk of LPV_COMPACT_CHUNK samples a word of live bits and a first place. */
size_t lpv_compact_head_bytes(size_t count);
/* Zeroes head (no sample live) before the producers mark theirs. */
void lpv_compact_clear(GLuint head);
/* Binds head where the producers mark the live samples (compact.glsl). */
void lpv_compact_bind(GLuint head);
/* Copies the marked samples of src[0, count) into dst (sized as src) and
 * writes the draw command (count, instances left as they are, first 0) at
 * the start of head; progs: compact.comp's scan and copy. */
void lpv_compact_run(const GLuint progs[2], GLuint src, size_t count, GLuint dst, GLuint head);

#endif /* LPV_COMPACT_H */
