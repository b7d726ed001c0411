/*
 * engine_item.c - one item of work (engine.h, lpv_engine_item): the order in
 * which a program hands the engine its inputs, written once for `lpvd
 * render`, `lpvd batch` and the daemon. Settings come first because the
 * scene's samples (surfels, area-light VPLs) depend on knobs: a scene set
 * before its settings would be sampled with the last item's and then again.
 */
#include "engine.h"

int lpv_engine_run_item(lpv_engine *e, const lpv_engine_item *it, char *err, size_t err_size)
{
    if (it->settings && lpv_engine_set_settings(e, it->settings, err, err_size) != 0)
        return -1;
    if (it->scene && lpv_engine_set_scene(e, it->scene, err, err_size) != 0)
        return -1;
    if (it->view && lpv_engine_set_view(e, it->view, err, err_size) != 0)
        return -1;
    if (it->recompute)
        lpv_engine_invalidate(e);
    if (it->forget)
        lpv_engine_forget(e);
    return it->tick ? lpv_engine_tick(e, err, err_size) : 0;
}
