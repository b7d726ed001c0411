/* report.c - a batch job's report: manifests in, thumbnails, contact sheet and
 * page out (report.h). */
#include "report.h"

#include "contact.h"
#include "image_io.h"
#include "manifest.h"
#include "report_html.h"
#include "thumbs.h"
#include "totals.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define PATH_SIZE 4096

static int path_in(char *out, const char *dir, const char *name, char *err, size_t err_size)
{
    if (name[0] == '/')
        snprintf(out, PATH_SIZE, "%s", name);
    else if ((size_t)snprintf(out, PATH_SIZE, "%s/%s", dir, name) >= PATH_SIZE) {
        snprintf(err, err_size, "%s/%s: path too long", dir, name);
        return -1;
    }
    return 0;
}

/* Item n's thumbnail into thumbs/<n>.png and tile n of the sheet. */
static void thumbnail(const char *dir, size_t n, const lpv_manifest_item *it, lpv_batch_contact *sheet,
                      lpv_batch_report_thumb *th, FILE *warnings)
{
    char src[PATH_SIZE], dst[PATH_SIZE], name[64], err[sizeof th->note];
    const char *image = lpv_batch_image_output(it->line);
    if (!image) {
        snprintf(th->note, sizeof th->note, "no PNG or EXR image output");
    } else if (path_in(src, dir, image, th->note, sizeof th->note) == 0) {
        lpv_batch_thumb t;
        if (lpv_batch_thumb_make(src, &t, err, sizeof err) != 0) {
            snprintf(th->note, sizeof th->note, "%s", err);
        } else {
            snprintf(name, sizeof name, "thumbs/%zu.png", n);
            if (path_in(dst, dir, name, th->note, sizeof th->note) == 0 &&
                lpv_image_write_u8(dst, t.width, t.height, 4, t.rgba, err, sizeof err) != 0)
                snprintf(th->note, sizeof th->note, "%s", err);
            else if (!th->note[0]) {
                th->made = 1;
                th->width = t.width;
                th->height = t.height;
                if (sheet->rgb)
                    lpv_batch_contact_put(sheet, n, &t);
            }
            lpv_batch_thumb_free(&t);
        }
    }
    if (!th->made && warnings)
        fprintf(warnings, "%s: item %s: no thumbnail: %s\n", dir, it->id, th->note);
}

/* The page, written beside and renamed over report.html. */
static int write_page(const char *dir, const lpv_manifest *m, const lpv_batch_totals *t,
                      const lpv_batch_report_thumb *thumbs, size_t contact_tiles, char *err, size_t err_size)
{
    char path[PATH_SIZE], tmp[PATH_SIZE];
    if (path_in(path, dir, "report.html", err, err_size) || path_in(tmp, dir, ".report.html.tmp", err, err_size))
        return -1;
    FILE *f = fopen(tmp, "w");
    if (!f) {
        snprintf(err, err_size, "%s: %s", tmp, strerror(errno));
        return -1;
    }
    const char *title = strrchr(dir, '/');
    title = title && title[1] ? title + 1 : dir;
    int rc = lpv_batch_report_html(f, title, m, t, thumbs, contact_tiles);
    if (fclose(f) != 0 || rc != 0) {
        snprintf(err, err_size, "%s: write failed", tmp);
        unlink(tmp);
        return -1;
    }
    if (rename(tmp, path) != 0) {
        snprintf(err, err_size, "%s: %s", path, strerror(errno));
        unlink(tmp);
        return -1;
    }
    return 0;
}

int lpv_batch_report(const char *dir, lpv_batch_report_summary *summary, FILE *warnings, char *err,
                     size_t err_size)
{
    lpv_manifest m;
    lpv_batch_totals t = {0};
    lpv_batch_contact sheet = {0};
    lpv_batch_report_thumb *thumbs = NULL;
    char path[PATH_SIZE];
    int rc = -1;
    if (summary)
        memset(summary, 0, sizeof *summary);
    if (lpv_manifest_read(dir, &m, warnings, err, err_size) != 0)
        goto done;
    if (lpv_batch_totals_compute(&m, &t) != 0) {
        snprintf(err, err_size, "%s: out of memory", dir);
        goto done;
    }
    thumbs = calloc(m.count ? m.count : 1, sizeof *thumbs);
    if (!thumbs) {
        snprintf(err, err_size, "%s: out of memory", dir);
        goto done;
    }
    if (path_in(path, dir, "thumbs", err, err_size) != 0)
        goto done;
    if (mkdir(path, 0777) != 0 && errno != EEXIST) {
        snprintf(err, err_size, "%s: %s", path, strerror(errno));
        goto done;
    }
    if (m.count && lpv_batch_contact_init(&sheet, m.count, err, err_size) != 0)
        goto done;
    for (size_t i = 0; i < m.count; i++) {
        if (lpv_manifest_item_ok(&m.items[i]))
            thumbnail(dir, i, &m.items[i], &sheet, &thumbs[i], warnings);
        else
            lpv_batch_contact_put_failed(&sheet, i);
    }
    if (path_in(path, dir, "contact.png", err, err_size) != 0)
        goto done;
    if (m.count) {
        if (lpv_batch_contact_write(&sheet, path, err, err_size) != 0)
            goto done;
    } else if (unlink(path) != 0 && errno != ENOENT) { /* a sheet from an earlier report would mislead */
        snprintf(err, err_size, "%s: %s", path, strerror(errno));
        goto done;
    }
    if (write_page(dir, &m, &t, thumbs, sheet.tiles, err, err_size) != 0)
        goto done;
    if (summary) {
        summary->items = t.items;
        summary->ok = t.ok;
        summary->failed = t.failed;
        summary->lines = m.lines;
        summary->skipped = m.skipped;
        summary->superseded = m.superseded;
        for (size_t i = 0; i < m.count; i++)
            if (lpv_manifest_item_ok(&m.items[i])) {
                if (thumbs[i].made)
                    summary->thumbs++;
                else
                    summary->thumbs_missing++;
            }
        summary->contact_tiles = sheet.tiles;
        summary->contact_width = sheet.width;
        summary->contact_height = sheet.height;
    }
    rc = 0;
done:
    free(thumbs);
    lpv_batch_contact_free(&sheet);
    lpv_batch_totals_free(&t);
    lpv_manifest_free(&m);
    return rc;
}
