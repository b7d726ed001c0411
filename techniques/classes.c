/*
 * classes.c - which class implements each technique of core/settings.h:
 * the one table the engine chooses from (settings.technique).
 */
#include "technique.h"

/* Each module's class (techniques/NAME/gpu/technique_NAME.c). */
extern const lpv_technique_class lpv_technique_cascaded_lpv;
extern const lpv_technique_class lpv_technique_octree;
extern const lpv_technique_class lpv_technique_iv;
extern const lpv_technique_class lpv_technique_probes;

static const lpv_technique_class *const CLASSES[LPV_TECHNIQUE_ID_COUNT_] = {
    [LPV_TECHNIQUE_ID_LPV] = &lpv_technique_cascaded_lpv,
    [LPV_TECHNIQUE_ID_OCTREE] = &lpv_technique_octree,
    [LPV_TECHNIQUE_ID_IV] = &lpv_technique_iv,
    [LPV_TECHNIQUE_ID_PROBES] = &lpv_technique_probes,
};

const lpv_technique_class *lpv_technique_class_of(lpv_technique_id id)
{
    if (id == LPV_TECHNIQUE_ID_DEFAULT)
        id = LPV_TECHNIQUE_ID_DEFAULT_IS;
    return (int)id > (int)LPV_TECHNIQUE_ID_DEFAULT && (int)id < (int)LPV_TECHNIQUE_ID_COUNT_ ? CLASSES[id] : NULL;
}
