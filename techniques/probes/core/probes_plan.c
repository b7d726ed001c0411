/*
 * probes_plan.c - the probes' plan and tick cost bound (probes_rules.h).
 */
#include "probes_rules.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cascades.h"
#include "lpv_shared.h"

void lpv_plan_make_probes(const lpv_settings *s, const lpv_plan_facts *f, const lpv_probes_progress *g,
                          lpv_plan *p)
{
    memset(p, 0, sizeof *p);
    const int all = s->planner == LPV_SWITCH_OFF;
    char why[LPV_PLAN_REASON_MAX];
    p->cascades = lpv_plan_cascades(s, f, why, sizeof why);
    snprintf(p->cascades_reason, sizeof p->cascades_reason, "%s: a probe per cell; %.90s", LPV_TECHNIQUE_PROBES, why);
    lpv_plan_render_passes(s, f, p, all);
    p->recompute = lpv_plan_needs_recompute(s, f, NULL, p->recompute_reason, sizeof p->recompute_reason);
    /* the probes read none of the shared producers but the light block,
     * which every tick fills: their rays see the scene itself */
    for (int i = 0; i < LPV_PASS_PROBES; ++i)
        if (i != LPV_PASS_GLOSSY && i != LPV_PASS_MEDIA && i != LPV_PASS_TRANSLUCENT)
            lpv_plan_decide(p, (lpv_pass_id)i, 0, "the probes trace the scene's triangles (technique %s)",
                            LPV_TECHNIQUE_PROBES);
    p->light_stale = f->first_tick || f->scene_changed || f->lights_changed || f->settings_changed;
    const int fresh = !g || !g->history;
    if (fresh && !p->recompute) { /* dropped (lpv_engine_forget) with nothing else changed */
        p->recompute = 1;
        snprintf(p->recompute_reason, sizeof p->recompute_reason, "no history");
    }
    if (all)
        lpv_plan_decide(p, LPV_PASS_PROBES, 1, "planner off");
    else if (p->recompute) /* also with no history: set above */
        lpv_plan_decide(p, LPV_PASS_PROBES, 1, "%s: %s", p->recompute_reason,
                        fresh       ? "every probe, warmup passes"
                        : g->scroll ? "warmup passes over the probes the cascades' move brings in, the others keep "
                                      "their light"
                                    : "a budget of probes");
    else if (g->refine > 0) {
        p->recompute = 1;
        snprintf(p->recompute_reason, sizeof p->recompute_reason,
                 "the probes the cascades' move brought in average more passes (%d of %d)", g->refine,
                 lpv_probes_refine_passes(s->probes.hysteresis, s->probes.warmup));
        lpv_plan_decide(p, LPV_PASS_PROBES, 1, "%s", p->recompute_reason);
    } else if (g->sweeps < lpv_probes_settle_sweeps(s->probes.hysteresis, g->changed)) {
        p->recompute = 1;
        snprintf(p->recompute_reason, sizeof p->recompute_reason, LPV_PROBES_SETTLE_REASON " (%d of %d sweeps)", g->sweeps,
                 lpv_probes_settle_sweeps(s->probes.hysteresis, g->changed));
        lpv_plan_decide(p, LPV_PASS_PROBES, 1, "%s", p->recompute_reason);
    } else
        lpv_plan_decide(p, LPV_PASS_PROBES, 0, "%s; the probes settled (%d sweeps since the last change)",
                        p->recompute_reason, g->sweeps);
}

long lpv_probes_scroll_source(const int dims[3], const int shift[LPV_MAX_CASCADES][3], size_t p)
{
    const size_t cells = (size_t)dims[0] * (size_t)dims[1] * (size_t)dims[2];
    const size_t k = p / cells, cell = p % cells;
    const int c[3] = {(int)(cell % (size_t)dims[0]), (int)(cell / (size_t)dims[0] % (size_t)dims[1]),
                      (int)(cell / ((size_t)dims[0] * (size_t)dims[1]))};
    int o[3];
    for (int i = 0; i < 3; ++i) {
        o[i] = c[i] + shift[k][i];
        if (o[i] < 0 || o[i] >= dims[i])
            return -1;
    }
    return (long)(k * cells + (size_t)o[0] + (size_t)dims[0] * ((size_t)o[1] + (size_t)dims[1] * (size_t)o[2]));
}

size_t lpv_probes_scroll_kept(const lpv_cascade_set *from, const lpv_cascade_set *to,
                              int shift[LPV_MAX_CASCADES][3], uint32_t *fresh, size_t *fresh_count)
{
    if (fresh_count)
        *fresh_count = 0;
    if (!from->snapped || !to->snapped || from->count != to->count || from->handoff != to->handoff ||
        to->count < 1 || to->count > LPV_MAX_CASCADES)
        return 0;
    size_t kept = 0;
    for (int k = 0; k < to->count; ++k) {
        if (from->grid[k].cell_size != to->grid[k].cell_size ||
            memcmp(from->grid[k].dims, to->grid[k].dims, sizeof to->grid[k].dims) != 0 ||
            memcmp(to->grid[k].dims, to->grid[0].dims, sizeof to->grid[k].dims) != 0)
            return 0;
        size_t stay = 1;
        for (int i = 0; i < 3; ++i) {
            const float d = to->origin_cells[k][i] - from->origin_cells[k][i];
            if (d != floorf(d) || fabsf(d) > (float)LPV_MAX_GRID_DIM)
                return 0;
            shift[k][i] = (int)d;
            const int n = to->grid[k].dims[i], s = abs(shift[k][i]);
            stay *= s < n ? (size_t)(n - s) : 0;
        }
        kept += stay;
    }
    if (fresh) {
        const size_t total = (size_t)to->count * lpv_grid_cell_count(&to->grid[0]);
        size_t n = 0;
        for (size_t p = 0; p < total; ++p)
            if (lpv_probes_scroll_source(to->grid[0].dims, shift, p) < 0)
                fresh[n++] = (uint32_t)p;
        *fresh_count = n;
    }
    return kept;
}

float lpv_probes_hysteresis_now(float hysteresis, const lpv_probes_progress *g)
{
    if (!g || !g->changed)
        return hysteresis;
    return hysteresis * (1.0f - powf(LPV_PROBES_CHANGE_RAMP, (float)(g->sweeps + 1)));
}

int lpv_probes_change_test_on(const lpv_probes_progress *g)
{
    return g && g->changed && g->sweeps < LPV_PROBES_CHANGE_TEST_SWEEPS;
}

int lpv_probes_settle_sweeps(float hysteresis, int changed)
{
    if (!(hysteresis > 0.0f) || !(hysteresis < 1.0f))
        return 1;
    if (!changed)
        return (int)ceil(log(LPV_PROBES_SETTLE_RESIDUE) / log((double)hysteresis));
    lpv_probes_progress g = {.history = 1, .changed = 1};
    double left = 1.0;
    for (g.sweeps = 0; left > LPV_PROBES_SETTLE_RESIDUE; ++g.sweeps)
        left *= (double)lpv_probes_hysteresis_now(hysteresis, &g);
    return g.sweeps;
}

int lpv_probes_refine_passes(float hysteresis, int warmup)
{
    const int n = hysteresis > 0.0f && hysteresis < 1.0f
                      ? (int)ceil((1.0 + (double)hysteresis) / (1.0 - (double)hysteresis) - 1e-9)
                      : 1;
    return n > warmup ? n : warmup;
}

uint64_t lpv_probes_bytes_per_probe(int oct)
{
    const uint64_t sh = 48, distances = 8ull * (uint64_t)oct * (uint64_t)oct,
                   irradiance = 12ull * LPV_PROBES_IRR_OCT * LPV_PROBES_IRR_OCT, state = 32, list = 4;
    return sh + distances + irradiance + state + list + (distances > irradiance ? distances : irradiance);
}

void lpv_probes_memory_need(const lpv_settings *s, size_t probes, uint64_t scene_bytes, lpv_memory_need *n)
{
    const uint64_t per = lpv_probes_bytes_per_probe(s->probes.oct), p = probes;
    const uint64_t batch = (uint64_t)s->probes.budget < p ? (uint64_t)s->probes.budget : p;
    const uint64_t rays = batch * (uint64_t)s->probes.rays * 16u,
                   distances = p * 8ull * (uint64_t)s->probes.oct * (uint64_t)s->probes.oct;
    n->cells += probes;
    n->technique_bytes += p * (per > LPV_MEM_CELL ? per - LPV_MEM_CELL : 0) + rays + scene_bytes;
    if (rays > n->technique_buffer) {
        n->technique_buffer = rays;
        n->technique_buffer_what = "the probes' ray results (probes_budget, at most every probe, x probes_rays x 16 B)";
        n->technique_buffer_lower = "probes_budget or probes_rays";
    }
    if (distances > n->technique_buffer) {
        n->technique_buffer = distances;
        n->technique_buffer_what = "the probes' distance maps (8 B x probes_oct^2 a probe)";
        n->technique_buffer_lower = "probes_oct, grid or cascades";
    }
}

void lpv_probes_memory_floor(const lpv_settings *s, lpv_memory_need *n)
{
    const int asked = s->lpv.cascades > 0 ? (s->lpv.cascades < LPV_MAX_CASCADES ? s->lpv.cascades : LPV_MAX_CASCADES) : 1;
    lpv_probes_memory_need(s, (size_t)lpv_settings_grid_cells(s) * (size_t)asked, 0, n);
    n->cascades = asked;
    memcpy(n->grid_dims, s->grid_dims, sizeof n->grid_dims);
}

void lpv_probes_tick_cost(const lpv_settings *s, lpv_tick_cost *out)
{
    /* the cascades the planner may place (auto: the most it places) */
    int cascades = s->lpv.cascades > 0 ? lpv_cascades_count(s, s->lpv.cascades) : lpv_cascades_count(s, 1);
    if (s->lpv.cascades <= 0 && cascades < LPV_AUTO_CASCADES)
        cascades = LPV_AUTO_CASCADES;
    const double cells = lpv_settings_grid_cells(s) * (double)cascades;
    const double per_pass = cells < (double)s->probes.budget ? cells : (double)s->probes.budget;
    const double first = cells * (double)s->probes.warmup;
    const double probes = first > per_pass ? first : per_pass;
    out->cell_steps = probes * s->probes.rays / LPV_TICK_COST_PROBES_RAYS_PER_STEP;
    snprintf(out->terms, sizeof out->terms,
             "%.0f probes (the first tick: %d warmup passes over %.0f; then probes_budget %d) x %d rays / %g rays a "
             "cell-step",
             probes, s->probes.warmup, cells, s->probes.budget, s->probes.rays, LPV_TICK_COST_PROBES_RAYS_PER_STEP);
    out->lower = "grid, probes_rays, probes_warmup or probes_budget";
}
