// probes_batch.glsl - which probe is a batch's j-th (probes_update.comp and
// probes_blend.comp): the round robin's (u_first + j) mod u_total, or, in a
// listed batch, entry u_first + j of the list (the probes a scrolled
// cascade brought in, which warm up alone while the others keep their
// light; technique_probes.c's scroll).
layout(std430, binding = LPV_SSBO_PROBES_LIST) readonly buffer ProbesList { uint probes_list[]; };

uniform uint u_first; // the batch's first probe (it wraps at u_total), or its first entry of the list
uniform uint u_batch; // probes in the batch
uniform uint u_total; // probes of every cascade
uniform int u_listed; // 1: the batch is the list's

uint probes_batch_probe(uint j) { return u_listed != 0 ? probes_list[u_first + j] : (u_first + j) % u_total; }
