/*
 * probes_rules.h - the probes' CPU half beside their BVH (probes_bvh.h),
 * ray math (probes_math.h) and CPU update (probes_update.h): the plan, the
 * tick cost bound and the knob rows, which techniques/registry.c and
 * technique_fields.c list.
 */
#ifndef LPV_PROBES_RULES_H
#define LPV_PROBES_RULES_H

#include <stddef.h>
#include <stdint.h>

#include "cascades.h"
#include "lpv_shared.h"
#include "memory_budget.h"
#include "plan.h"
#include "settings_fields.h"
#include "tick_cost.h"

/* The update's fixed shape (techniques/probes/README.md "The update"). */
#define LPV_PROBES_SHARPNESS 50.0f   /* a ray's weight in a distance texel: max(0, cos)^this (the paper's) */
#define LPV_PROBES_MOMENT_CELLS 2.0f /* the distance moments clamp hits at this many cells */
#define LPV_PROBES_BACKFACE_OFF 0.25f /* a probe whose rays hit back faces more often is off */
#define LPV_PROBES_BIAS_CELLS 0.25f  /* the lookup's point moves this far along the normal (cells) */
/* Relocation (Majercik et al. 2021), on a fresh volume's first pass: a probe
 * that is off moves out through its closest back face, one nearer a surface
 * than this many cells moves away from it, neither beyond
 * LPV_PROBES_MAX_OFFSET_CELLS of its cell's centre on any axis. */
#define LPV_PROBES_MIN_FRONT_CELLS 0.2f
#define LPV_PROBES_MAX_OFFSET_CELLS 0.45f
#define LPV_PROBES_SEED 1u           /* the ray set's rotations (lpv_probes_rotation) */
/* A static scene stops tracing once every probe was updated often enough
 * after the last change for the light from before it to weigh at most this
 * (the product of the sweeps' hysteresis, lpv_probes_settle_sweeps). */
#define LPV_PROBES_SETTLE_RESIDUE 0.01
/* The plan's recompute reason while they settle (the tick tells a change
 * by the plan's light_stale, not by the reason). */
#define LPV_PROBES_SETTLE_REASON "the probes settle"

/* The state the plan reads from the technique (the GPU class keeps it). */
typedef struct lpv_probes_progress {
    int history;  /* 1: the probes hold light from earlier ticks */
    int sweeps;   /* full sweeps over every probe since the last change */
    int changed;  /* 1: sweeps counts from a change of the scene or lights (0: from a warmup) */
    int scroll;   /* 1: the camera moves the cascades by whole cells and some probes stay
                     (lpv_probes_scroll_kept): only the probes it brings in warm up */
    int refine;   /* passes averaged so far over the probes the last scroll brought in, while under
                     lpv_probes_refine_passes (0: none refining) */
    size_t probes;
} lpv_probes_progress;

/* The hysteresis of the sweeps after a change (a light moved, a knob of
 * the volume): h x (1 - LPV_PROBES_CHANGE_RAMP^(sweeps + 1)), so the first
 * sweep after it keeps half as much of the old light and the weight climbs
 * back to h over a few sweeps; a light that moves every tick keeps the
 * probes at the low end (fast and noisier), a still one lets them average.
 * After a warmup (no old light to forget) h itself. */
#define LPV_PROBES_CHANGE_RAMP 0.5f
float lpv_probes_hysteresis_now(float hysteresis, const lpv_probes_progress *g);

/* Whether the blend's per-probe change test (probes_blend.comp) runs: only
 * in the first LPV_PROBES_CHANGE_TEST_SWEEPS sweeps after a change, to
 * follow it fast. Not after a warmup nor once the light has been still that
 * long: it resets a probe toward any batch far from its old value, by ratio
 * either way, which tracks a skewed radiance (a few rays through the blinds'
 * slats) in the log and settles it dark (blinds at 32^3: bias -0.27 after
 * five sweeps with the test always on, docs/accuracy.md). */
#define LPV_PROBES_CHANGE_TEST_SWEEPS 4
int lpv_probes_change_test_on(const lpv_probes_progress *g);

/* The probes' plan: the shared producers (none but the frame's: the light
 * block comes with every tick) and their pass, which runs on a change and
 * until the probes settled. */
void lpv_plan_make_probes(const lpv_settings *s, const lpv_plan_facts *f, const lpv_probes_progress *g,
                          lpv_plan *out);

/* Sweeps over every probe after a change (changed 1) or a warmup (0)
 * until the probes settled: the least n for which the product of the n
 * sweeps' hysteresis (lpv_probes_hysteresis_now) is at most
 * LPV_PROBES_SETTLE_RESIDUE: at 0.9, 44 after a warmup (0.9^n), 32 after a
 * change (the ramp forgets faster). An upper bound: the blend lowers the
 * hysteresis further where a probe's light changed. */
int lpv_probes_settle_sweeps(float hysteresis, int changed);

/* The passes the probes a scroll brought in average before they stop:
 * as many as the settled probes' running blend weighs, (1 + h) / (1 - h)
 * (its variance is (1 - h) / (1 + h) of one update's; 19 at h 0.9), so
 * the slab is no noisier than the probes beside it. At least `warmup`
 * (its averaged passes count). */
int lpv_probes_refine_passes(float hysteresis, int warmup);

/* Whole cells each cascade moves from `from` to `to` (a new cell's old cell
 * is cell + shift[k]) and the probes whose cells both hold, which keep
 * their light: 0 when they are not camera-following cascades of the same
 * count, dims and cell sizes (nothing carries over), or no cell stays.
 * With `fresh` (room for every probe of `to`), also lists the indices of
 * the probes the move brings in, in order, and sets *fresh_count. The one
 * rule the plan, commit's list and probes_scroll.comp's copy follow (the
 * shader mirrors lpv_probes_scroll_source). */
size_t lpv_probes_scroll_kept(const lpv_cascade_set *from, const lpv_cascade_set *to,
                              int shift[LPV_MAX_CASCADES][3], uint32_t *fresh, size_t *fresh_count);
/* The index of the probe in the old layout whose light probe `p` of the
 * new one takes, or -1 when the move brought `p` in (probes_scroll.comp
 * computes the same). */
long lpv_probes_scroll_source(const int dims[3], const int shift[LPV_MAX_CASCADES][3], size_t p);

/* Probes a tick (budget, or every probe of the grid's cascades on the
 * first tick's warmup) x rays, at LPV_TICK_COST_PROBES_RAYS_PER_STEP a
 * cell-step. */
void lpv_probes_tick_cost(const lpv_settings *s, lpv_tick_cost *out);

/* Bytes a probe holds (technique_probes.c's buffers): its SH (48), distance
 * map (2 floats a texel, oct^2 texels), irradiance map (3 floats a texel,
 * LPV_PROBES_IRR_OCT^2), state (8 floats) and place in a scroll's list (4),
 * and the scroll's copy of the largest of those maps (it copies one buffer
 * at a time). */
uint64_t lpv_probes_bytes_per_probe(int oct);
/* Adds the probes' storage to n: `probes` cells (LPV_MEM_CELL of each
 * probe's bytes), the rest of each probe's, a batch's ray results
 * (min(probes_budget, probes) x probes_rays x 16 B) and the scene's BVH and
 * triangles (scene_bytes); the largest single buffer of them for the
 * max_buffer check. */
void lpv_probes_memory_need(const lpv_settings *s, size_t probes, uint64_t scene_bytes, lpv_memory_need *n);
/* The least any scene needs: a probe per cell of the cascades asked for
 * (one grid unless lpv.cascades is set), no scene (techniques/registry.c). */
void lpv_probes_memory_floor(const lpv_settings *s, lpv_memory_need *n);

/* Its knob rows (probes_fields.c), *count of them. */
const lpv_field *lpv_probes_fields(size_t *count);

#endif
