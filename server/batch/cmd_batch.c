/*
 * cmd_batch.c - `lpvd batch JOB.json --out DIR`: every work item of a job
 * file (server/batch/batch_job.h) in one process with one GL context, scenes
 * loaded once and their items run back to back, so the engine recomputes
 * only what changed between two items. Resumable: outputs are written under
 * a temporary name and renamed when complete, then the item's manifest line
 * is appended (server/batch/batch_manifest.h); a re-run skips every item whose
 * line says ok and whose outputs exist. SIGTERM / SIGINT finish the item in
 * flight and exit. Sharded with --shard I/N or Kubernetes' Indexed Job
 * environment (docs/batch.md).
 */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "batch_job.h"
#include "batch_manifest.h"
#include "batch_render.h"
#include "commands.h"
#include "manifest.h"
#include "report.h"
#include "options.h"

enum { B_OUT, B_SHARD, B_LIST, B_MERGE, B_REPORT, B_PROGRESS, B_HELP, B_COUNT };

static const lpv_flag BATCH_FLAGS[B_COUNT] = {
    [B_OUT] = {"out", 'o', "DIR", "the output folder: images, manifests, report (required but for --list)"},
    [B_SHARD] = {"shard", 0, "I/N", "render shard I of N (0-based); default: JOB_COMPLETION_INDEX of\n"
                                   "LPVD_SHARDS from the environment (a Kubernetes Indexed Job), else 0/1"},
    [B_LIST] = {"list", 0, NULL, "print the job's items (index, id, shard) and exit"},
    [B_MERGE] = {"merge", 0, NULL, "combine DIR's shard manifests into DIR/manifest.jsonl and exit"},
    [B_REPORT] = {"report", 0, NULL, "write DIR/report.html, DIR/contact.png and DIR/thumbs/ from DIR's\n"
                                    "manifests and exit (with --merge: after merging); a run of the\n"
                                    "whole job (shard 0/1) writes them at its end"},
    [B_PROGRESS] = {"progress", 0, "auto|bar|lines|off", "progress on stderr (auto: a bar on a terminal, else lines)"},
    [B_HELP] = {"help", 'h', NULL, "this text"},
};

static void usage(FILE *f, const lpv_flag_group *backend)
{
    char help[4096], gl[1024];
    size_t len = 0, glen = 0;
    lpv_flags_help(help, sizeof help, &len, BATCH_FLAGS, B_COUNT);
    lpv_flags_help(gl, sizeof gl, &glen, backend->flags, backend->count); /* options.c's table */
    fprintf(f,
            "usage: lpvd batch JOB.json --out DIR [flags]\n"
            "Renders every item of a job file (docs/batch.md); re-running resumes.\n"
            "Exit status: 0 every item of the shard done, 1 an item failed, 2 a bad command line\n"
            "or job file, 3 stopped by a signal before the shard was done (run again to resume).\n%s"
            "GL:\n%s",
            help, gl);
}

/* The shard from the command line, else the Indexed Job's environment. */
static int shard_of(const char *flag, int *i, int *n, char *err, size_t err_size)
{
    if (flag)
        return lpvd_batch_parse_shard(flag, i, n, err, err_size);
    const char *idx = getenv("JOB_COMPLETION_INDEX"), *count = getenv("LPVD_SHARDS");
    if (!idx && !count) {
        *i = 0;
        *n = 1;
        return 0;
    }
    if (!idx || !count) {
        snprintf(err, err_size, "JOB_COMPLETION_INDEX and LPVD_SHARDS must be set together (got %s only)",
                 idx ? "JOB_COMPLETION_INDEX" : "LPVD_SHARDS");
        return -1;
    }
    char text[64];
    snprintf(text, sizeof text, "%s/%s", idx, count);
    if (lpvd_batch_parse_shard(text, i, n, err, err_size) != 0) {
        snprintf(err, err_size, "JOB_COMPLETION_INDEX=%s, LPVD_SHARDS=%s: expected 0 <= index < shards <= 100000",
                 idx, count);
        return -1;
    }
    return 0;
}

static volatile sig_atomic_t g_stop;
static void on_signal(int sig) { g_stop = sig; }

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Progress on stderr: a bar redrawn in place on a terminal, else a line per item. */
typedef struct progress {
    int mode; /* 0 off, 1 lines, 2 bar */
    int total, done, failed, skipped;
    double start;
} progress;

static void progress_show(progress *p, const char *id, const char *status, double ms)
{
    if (p->mode == 0)
        return;
    int n = p->done + p->failed;
    double el = now_s() - p->start, rate = el > 0.0 ? n / el : 0.0;
    double left = rate > 0.0 ? (p->total - p->skipped - n) / rate : 0.0;
    if (p->mode == 1) {
        fprintf(stderr, "lpvd batch: %d/%d %s %s %.0f ms (%.1f items/min, %.0f s left)\n", n + p->skipped, p->total,
                id, status, ms, 60.0 * rate, left);
        return;
    }
    int width = 30, fill = p->total ? (int)((double)(n + p->skipped) / p->total * width) : width;
    fprintf(stderr, "\r\033[K[%.*s%*s] %d/%d items, %d failed, %.1f items/min, %02d:%02d left", fill,
            "##############################", width - fill, "", n + p->skipped, p->total, p->failed, 60.0 * rate,
            (int)(left / 60.0), (int)fmod(left, 60.0));
    if (n + p->skipped == p->total)
        fputc('\n', stderr);
}

static int mkdirs(const char *path)
{
    char buf[4096];
    snprintf(buf, sizeof buf, "%s", path);
    for (char *p = buf + 1; *p; ++p)
        if (*p == '/') {
            *p = '\0';
            if (mkdir(buf, 0777) != 0 && errno != EEXIST)
                return -1;
            *p = '/';
        }
    return mkdir(buf, 0777) != 0 && errno != EEXIST ? -1 : 0;
}

/* An ok entry whose outputs all exist: the item is done. */
static int entry_done(const char *dir, const json_t *e)
{
    if (!e || strcmp(json_string_value(json_object_get(e, "status")) ? json_string_value(json_object_get(e, "status"))
                                                                    : "",
                     "ok") != 0)
        return 0;
    const json_t *outs = json_object_get(e, "outputs");
    size_t i;
    json_t *o;
    json_array_foreach(outs, i, o)
    {
        char path[4096];
        struct stat st;
        snprintf(path, sizeof path, "%s/%s", dir, json_string_value(json_object_get(o, "path")));
        if (stat(path, &st) != 0 || !S_ISREG(st.st_mode))
            return 0;
    }
    return json_array_size(outs) > 0;
}

/* The report of DIR's manifests (report/report.h). */
static int write_report(const char *dir)
{
    char err[1024];
    lpv_batch_report_summary s;
    if (lpv_batch_report(dir, &s, stderr, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd batch: report: %s\n", err);
        return -1;
    }
    fprintf(stderr, "lpvd batch: report: %s/report.html (%ld ok, %ld failed)%s\n", dir, s.ok, s.failed,
            s.contact_tiles ? ", contact.png" : "");
    return 0;
}

static int do_list(const lpvd_batch_job *job, int shard, int shards, int shard_given)
{
    unsigned char *mine = malloc((size_t)job->item_count + 1);
    if (!mine)
        return 1;
    for (int s = 0; s < shards; ++s) {
        if (shard_given && s != shard)
            continue;
        lpvd_batch_shard(job, s, shards, mine);
        for (int k = 0; k < job->item_count; ++k)
            if (mine[k])
                printf("%d\t%s\t%d/%d\n", job->items[k].index, job->items[k].id, s, shards);
    }
    free(mine);
    return 0;
}

int lpvd_cmd_batch(int argc, char **argv)
{
    /* first of all: in a container lpvd is PID 1, and the kernel drops a
     * SIGTERM sent to a PID 1 that has no handler, so one arriving while the
     * job file is read would be lost */
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGINT, &sa, NULL);
    lpvd_options opt = {0};
    const char *job_path = NULL, *out = NULL, *shard_flag = NULL, *progress_mode = "auto";
    int list = 0, merge = 0, report = 0;
    char err[1024] = "";
    lpv_flag_group groups[2] = {{BATCH_FLAGS, B_COUNT, NULL, NULL}};
    int ngroups = 1 + lpvd_options_groups(&opt, LPVD_GROUP_BACKEND, 1, groups + 1);
    lpv_flags p;
    if (lpv_flags_begin(&p, argc, argv, groups, ngroups, 0) != 0) {
        fprintf(stderr, "lpvd batch: %s\n", p.err);
        return 2;
    }
    int g;
    const lpv_flag *fl;
    const char *v;
    for (lpv_flags_item it; (it = lpv_flags_next(&p, &g, &fl, &v)) != LPV_FLAGS_END;) {
        if (lpv_flags_refuse(&p, it, v, "lpvd batch", 1))
            return 2;
        if (it == LPV_FLAGS_POSITIONAL) {
            if (job_path) {
                fprintf(stderr, "lpvd batch: more than one job file given (%s, %s)\n", job_path, v);
                return 2;
            }
            job_path = v;
            continue;
        }
        switch (fl - BATCH_FLAGS) {
        case B_HELP: usage(stdout, &groups[1]); return 0;
        case B_OUT: out = v; break;
        case B_SHARD: shard_flag = v; break;
        case B_LIST: list = 1; break;
        case B_MERGE: merge = 1; break;
        case B_REPORT: report = 1; break;
        case B_PROGRESS: progress_mode = v; break;
        }
    }
    int pmode = strcmp(progress_mode, "auto") == 0 ? (isatty(STDERR_FILENO) ? 2 : 1)
                : strcmp(progress_mode, "bar") == 0   ? 2
                : strcmp(progress_mode, "lines") == 0 ? 1
                : strcmp(progress_mode, "off") == 0   ? 0
                                                      : -1;
    if (pmode < 0) {
        fprintf(stderr, "lpvd batch: --progress %s: expected auto, bar, lines or off\n", progress_mode);
        return 2;
    }
    if (!out && (merge || report || !list)) {
        fprintf(stderr, "lpvd batch: --out DIR is required\n");
        return 2;
    }
    if (merge || report) {
        int skipped = 0;
        int n = merge ? lpvd_manifest_merge(out, &skipped, err, sizeof err) : 0;
        if (n < 0) {
            fprintf(stderr, "lpvd batch: --merge: %s\n", err);
            return 1;
        }
        if (merge)
            fprintf(stderr, "lpvd batch: merged %d items into %s/manifest.jsonl%s\n", n, out,
                    skipped ? " (unreadable lines skipped)" : "");
        return report && write_report(out) != 0 ? 1 : 0;
    }
    if (!job_path) {
        fprintf(stderr, "lpvd batch: no job file given (see lpvd batch --help)\n");
        return 2;
    }
    int shard = 0, shards = 1;
    if (shard_of(shard_flag, &shard, &shards, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd batch: %s\n", err);
        return 2;
    }
    lpvd_batch_job job;
    if (lpvd_batch_job_load(job_path, &job, err, sizeof err) != 0) {
        fprintf(stderr, "lpvd batch: %s\n", err);
        return 2;
    }
    if (list) {
        int rc = do_list(&job, shard, shards, shard_flag || getenv("JOB_COMPLETION_INDEX"));
        lpvd_batch_job_free(&job);
        return rc;
    }
    int rc = 1;
    unsigned char *mine = malloc((size_t)job.item_count + 1);
    lpv_manifest done;
    memset(&done, 0, sizeof done);
    FILE *manifest = NULL;
    lpvd_batch_renderer *r = NULL;
    if (!mine || mkdirs(out) != 0) {
        fprintf(stderr, "lpvd batch: %s: %s\n", out, mine ? strerror(errno) : "out of memory");
        goto end;
    }
    int count = lpvd_batch_shard(&job, shard, shards, mine);
    if (lpv_manifest_read_any(out, &done, stderr, err, sizeof err) != 0 ||
        !(manifest = lpvd_manifest_open(out, shard, shards, err, sizeof err))) {
        fprintf(stderr, "lpvd batch: %s\n", err);
        goto end;
    }
    if (done.skipped)
        fprintf(stderr, "lpvd batch: %ld unreadable manifest line(s) skipped (their items run again)\n",
                done.skipped);
    progress pr = {.mode = pmode, .total = count, .start = now_s()};
    json_t *by_id = json_object(); /* the job's items by id: a manifest line names its item by id */
    for (int k = 0; by_id && k < job.item_count; ++k)
        json_object_set_new(by_id, job.items[k].id, json_integer(k));
    for (size_t i = 0; by_id && i < done.count; ++i) {
        const json_t *pos = json_object_get(by_id, done.items[i].id);
        json_int_t k = pos ? json_integer_value(pos) : -1;
        if (k >= 0 && mine[k] && entry_done(out, done.items[i].line)) {
            mine[k] = 0;
            pr.skipped++;
        }
    }
    json_decref(by_id);
    fprintf(stderr, "lpvd batch: %s: %d items, shard %d/%d has %d, %d already done\n", job_path, job.item_count,
            shard, shards, count, pr.skipped);
    if (pr.skipped < count) {
        r = lpvd_batch_renderer_create(&job, opt.backend, out, err, sizeof err);
        if (!r) {
            fprintf(stderr, "lpvd batch: %s\n", err);
            goto end;
        }
    }
    int failed = 0, left = count - pr.skipped;
    for (int k = 0; k < job.item_count && !g_stop; ++k) {
        if (!mine[k])
            continue;
        json_t *entry = lpvd_batch_render_item(r, &job.items[k]);
        const char *status = json_string_value(json_object_get(entry, "status"));
        int ok = status && strcmp(status, "ok") == 0;
        json_object_set_new(entry, "shard", json_pack("[i,i]", shard, shards));
        if (lpvd_manifest_append(manifest, entry) != 0) {
            fprintf(stderr, "lpvd batch: %s: cannot append to the manifest: %s\n", out, strerror(errno));
            json_decref(entry);
            goto end;
        }
        if (!ok)
            fprintf(stderr, "%slpvd batch: %s failed: %s\n", pr.mode == 2 ? "\r\033[K" : "", job.items[k].id,
                    json_string_value(json_object_get(entry, "error")));
        ok ? pr.done++ : pr.failed++;
        failed += !ok;
        --left;
        progress_show(&pr, job.items[k].id, ok ? "ok" : "failed",
                      json_real_value(json_object_get(json_object_get(entry, "ms"), "total")));
        json_decref(entry);
    }
    if (g_stop && left > 0) {
        fprintf(stderr, "%slpvd batch: stopped by signal %d after the item in flight; %d item(s) left, run again to "
                        "resume\n",
                pr.mode == 2 ? "\n" : "", (int)g_stop, left);
        rc = failed ? 1 : 3;
    } else {
        fprintf(stderr, "lpvd batch: shard %d/%d: %d done, %d failed, %d skipped (done before)\n", shard, shards,
                pr.done, pr.failed, pr.skipped);
        rc = failed ? 1 : 0;
        if (shards == 1 && pr.done + pr.failed > 0 && write_report(out) != 0)
            rc = 1;
    }
end:
    lpvd_batch_renderer_destroy(r);
    if (manifest)
        fclose(manifest);
    lpv_manifest_free(&done);
    free(mine);
    lpvd_batch_job_free(&job);
    return rc;
}
