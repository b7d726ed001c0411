/*
 * memory_limits.h - the current GL context's storage limits for
 * core/memory_budget.h: the budget (half of the video memory the driver
 * reports through GL_NVX_gpu_memory_info or GL_ATI_meminfo, else half of the
 * machine's RAM, which is the memory of llvmpipe; the environment variable
 * LPVD_MEMORY_BUDGET_MB, in 10^6 bytes, lowers it), the largest shader storage
 * buffer, texture side and array layers. The engine's side of the check
 * (lpv_engine_memory_need / _check) is declared in engine_internal.h.
 */
#ifndef LPV_MEMORY_LIMITS_H
#define LPV_MEMORY_LIMITS_H

#include "memory_budget.h"

/* Reads the limits of the context current on this thread. */
void lpv_memory_limits_query(lpv_memory_limits *out);

#endif /* LPV_MEMORY_LIMITS_H */
