/* serve_memory.c - the daemon's one memory budget (see serve_memory.h). */
#include "serve_memory.h"

#include <stdio.h>
#include <string.h>
#include <unistd.h>

static const char *const k_names[SV_MEM_TERMS] = {"worlds", "scenes", "requests", "replies", "bases",
                                                            "encodings"};

const char *sv_mem_term_name(sv_mem_term t)
{
    return (unsigned)t < SV_MEM_TERMS ? k_names[t] : "?";
}

/* A cgroup's limit in bytes from one of its files ("max": none). */
static uint64_t cgroup_limit(const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return 0;
    unsigned long long v = 0;
    int n = fscanf(f, "%llu", &v);
    fclose(f);
    return n == 1 ? (uint64_t)v : 0;
}

uint64_t sv_memory_machine(void)
{
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    uint64_t ram = pages > 0 && page > 0 ? (uint64_t)pages * (uint64_t)page : 0;
    /* cgroup v2, then v1 (v1 says "no limit" with a huge number) */
    const char *files[] = {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; ++i) {
        uint64_t lim = cgroup_limit(files[i]);
        if (lim && (!ram || lim < ram))
            ram = lim;
    }
    return ram;
}

int sv_memory_init(sv_memory *m, uint64_t flag_bytes, uint64_t headroom, char *err, size_t err_size)
{
    memset(m, 0, sizeof *m);
    m->headroom = headroom;
    if (flag_bytes) {
        m->budget = flag_bytes;
        snprintf(m->source, sizeof m->source, "--max-memory %llu", (unsigned long long)flag_bytes);
    } else {
        const uint64_t machine = sv_memory_machine();
        m->budget = machine / 2;
        snprintf(m->source, sizeof m->source, "half of the machine's %.2f GB (--max-memory)", (double)machine / 1e9);
    }
    if (m->budget <= headroom) {
        snprintf(err, err_size, "the memory budget, %s, leaves no room beside one message of --max-message %llu",
                 m->source, (unsigned long long)headroom);
        return -1;
    }
    return 0;
}

void sv_memory_add(sv_memory *m, sv_mem_term t, uint64_t bytes)
{
    atomic_fetch_add_explicit(&m->held[t], bytes, memory_order_relaxed);
}

void sv_memory_sub(sv_memory *m, sv_mem_term t, uint64_t bytes)
{
    atomic_fetch_sub_explicit(&m->held[t], bytes, memory_order_relaxed);
}

uint64_t sv_memory_held(const sv_memory *m, sv_mem_term t)
{
    return atomic_load_explicit(&m->held[t], memory_order_relaxed);
}

uint64_t sv_memory_total(const sv_memory *m)
{
    uint64_t sum = 0;
    for (int t = 0; t < SV_MEM_TERMS; ++t)
        sum += sv_memory_held(m, (sv_mem_term)t);
    return sum;
}

uint64_t sv_memory_room(const sv_memory *m, sv_mem_term t)
{
    const uint64_t others = sv_memory_total(m) - sv_memory_held(m, t);
    const uint64_t reserve = others + (t == SV_MEM_REQUESTS ? 0 : m->headroom);
    return m->budget > reserve ? m->budget - reserve : 0;
}

int sv_memory_fits(const sv_memory *m, sv_mem_term t, uint64_t more)
{
    const uint64_t own = sv_memory_held(m, t);
    return own + more >= own && own + more <= sv_memory_room(m, t);
}

void sv_memory_describe(const sv_memory *m, char *buf, size_t size)
{
    snprintf(buf, size, "the daemon's memory budget, %s, %.3f GB, holds worlds %.3f GB, scenes %.3f GB, requests %.3f GB, "
                        "replies %.3f GB, bases %.3f GB, encodings %.3f GB (and keeps %.3f GB free for one "
                        "--max-message)",
             m->source, (double)m->budget / 1e9, (double)sv_memory_held(m, SV_MEM_WORLDS) / 1e9,
             (double)sv_memory_held(m, SV_MEM_SCENES) / 1e9, (double)sv_memory_held(m, SV_MEM_REQUESTS) / 1e9,
             (double)sv_memory_held(m, SV_MEM_REPLIES) / 1e9,
             (double)sv_memory_held(m, SV_MEM_BASES) / 1e9, (double)sv_memory_held(m, SV_MEM_ENCODINGS) / 1e9,
             (double)m->headroom / 1e9);
}
