/*
 * batch_render.h - renders lpvd batch's work items: one GL context and one
 * engine for a whole run, the scene (at an animation time) loaded once for
 * the consecutive items that use it, and each item's settings, lights and
 * camera handed to the engine, which recomputes only what they change.
 */
#ifndef LPVD_BATCH_RENDER_H
#define LPVD_BATCH_RENDER_H

#include <stddef.h>

#include <jansson.h>

#include "batch_job.h"
#include "context.h"

typedef struct lpvd_batch_renderer lpvd_batch_renderer;

/* A context on backend, an engine, outputs under out_dir. NULL with a
 * message in err. */
lpvd_batch_renderer *lpvd_batch_renderer_create(const lpvd_batch_job *job, lpv_backend backend, const char *out_dir,
                                                char *err, size_t err_size);
void lpvd_batch_renderer_destroy(lpvd_batch_renderer *r);

/* Renders one item and writes its outputs (each under a temporary name,
 * renamed once complete). Returns its manifest entry (docs/batch.md): id,
 * index, scene, time, camera, lights, settings, outputs, status "ok" or
 * "failed" with "error", ms {load, tick, render, write, total}, stages (GPU
 * ms per engine stage), plan, started, finished. Never NULL but out of
 * memory. */
json_t *lpvd_batch_render_item(lpvd_batch_renderer *r, const lpvd_batch_item *item);

#endif
