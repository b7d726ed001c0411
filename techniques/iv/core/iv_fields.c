/*
 * iv_fields.c - imperfect volumes' knob rows (core/settings_fields.h): each
 * knob's range, default, help and what a change recomputes, written once.
 * The registry's row hands them to the knob table (lpv_fields), after
 * core's rows.
 */
#include "iv_rules.h"

#include "lpv_shared.h"

#include "settings_rows.h"

static const lpv_field IV_FIELDS[] = {
    /* Imperfect volumes (docs/imperfect-volumes.md). */
    {"iv_resolution", "iv-resolution", LPV_FIELD_INT, F(iv.resolution), 1, LPV_MAX_GRID_DIM, 0, "voxels", D(16), "",
     "voxels along the scene's longest side (more in long scenes: a quarter of the free path each, within this cube's count)",
     T_VOL, LPV_TECHNIQUE_IV},
    {"iv_points", "iv-points", LPV_FIELD_INT, F(iv.points), 1, LPV_IV_MAX_POINTS_PER_TRIANGLE, 0, "", D(1), "",
     "random points per triangle (Turk's formula)", T_VOL | T_SAMPLES, LPV_TECHNIQUE_IV},
    {"iv_split", "iv-split", LPV_FIELD_FLOAT, F(iv.split), 0, 1e6, 1, "voxels", D(0.5), "",
     "triangles with a longer edge are split before sampling", T_VOL | T_SAMPLES, LPV_TECHNIQUE_IV},
    {"iv_seed", "iv-seed", LPV_FIELD_INT, F(iv.seed), 1, LPV_IV_MAX_SEED, 0, "", D(1), "",
     "random seed of the points and the rays", T_VOL | T_SAMPLES, LPV_TECHNIQUE_IV},
    {"iv_rays", "iv-rays", LPV_FIELD_INT, F(iv.rays), 1, LPV_IV_MAX_RAYS, 0, "", D(128), "",
     "stratified rays marched per voxel", T_VOL, LPV_TECHNIQUE_IV},
    {"iv_bounces", "iv-bounces", LPV_FIELD_INT, F(iv.bounces), 1, LPV_IV_MAX_BOUNCES, 0, "", D(4), "",
     "diffuse bounces (ping-pong passes over two volumes)", T_VOL, LPV_TECHNIQUE_IV},
    {"iv_tail", "iv-tail", LPV_FIELD_SWITCH, F(iv.tail), 0, 1, 0, "", D(1), "",
     "the bounces after iv_bounces (3 or more) as the series the last ones set", T_VOL, LPV_TECHNIQUE_IV},
    {"iv_filter", "iv-filter", LPV_FIELD_SWITCH, F(iv.filter), 0, 1, 0, "", D(1), "",
     "after the last bounce each surface voxel takes the 3 x 3 mean of its plane's (less ray noise)", T_VOL,
     LPV_TECHNIQUE_IV},
    {"iv_reprojection", "iv-reprojection", LPV_FIELD_SWITCH, F(iv.reprojection), 0, 1, 0, "", D(1), "",
     "the camera's visible points refine the volume", T_VOL, LPV_TECHNIQUE_IV},
    {"iv_neighbours", "iv-neighbours", LPV_FIELD_INT, F(iv.neighbours), 1, 8, 0, "", D(8), "the paper's text: 6",
     "nearest of the 8 voxels around the shifted point the reconstruction blends", T_VOL | T_SHADE,
     LPV_TECHNIQUE_IV},
    {"iv_ao", "iv-ao", LPV_FIELD_SWITCH, F(iv.ao), 0, 1, 0, "", D(0), "",
     "ambient occlusion volume (the ao frame term)", T_VOL, LPV_TECHNIQUE_IV},
    {"iv_ao_distance", "iv-ao-distance", LPV_FIELD_FLOAT, F(iv.ao_distance), 0, 1e6, 0, "m", D_ZERO("auto"),
     "0 = auto: 4 voxels", "reach of the ambient occlusion rays", T_VOL, LPV_TECHNIQUE_IV},
    {"iv_max_points", "iv-max-points", LPV_FIELD_INT, F(iv.max_points), 1, LPV_IV_MAX_POINTS, 0, "", D(1 << 20), "",
     "point cloud budget (more triangles get fewer points each)", T_VOL | T_SAMPLES, LPV_TECHNIQUE_IV},
};

#include "settings_rows_end.h"

const lpv_field *lpv_iv_fields(size_t *count)
{
    *count = sizeof IV_FIELDS / sizeof IV_FIELDS[0];
    return IV_FIELDS;
}
