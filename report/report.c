/* report.c - a batch job's report: manifests in, thumbnails, contact sheet and
 * page out (report.h). */
#include "report.h"

#include "contact.h"
#include "image_io.h"
#include "manifest.h"
#include "report_html.h"
#include "thumbs.h"
#include "totals.h"
#include "write_beneath.h"

#include <errno.h>
#include <fcntl.h>
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

/* Writers for lpv_write_beneath: every file the report makes is written
 * beneath the job folder and never through a link (a linked thumbs/ or
 * contact.png would have had its target overwritten; issue 31, item 7). */
static int write_thumb(const char *path, void *arg, char *err, size_t err_size)
{
    const lpv_batch_thumb *t = arg;
    return lpv_image_write_u8(path, t->width, t->height, 4, t->rgba, err, err_size);
}

static int write_contact(const char *path, void *arg, char *err, size_t err_size)
{
    return lpv_batch_contact_write(arg, path, err, err_size);
}

typedef struct page {
    const char *title;
    const lpv_manifest *m;
    const lpv_batch_totals *t;
    const lpv_batch_report_thumb *thumbs;
    size_t contact_tiles;
} page;

static int write_page(const char *path, void *arg, char *err, size_t err_size)
{
    const page *p = arg;
    FILE *f = fopen(path, "w");
    if (!f) {
        snprintf(err, err_size, "report.html: %s", strerror(errno));
        return -1;
    }
    int rc = lpv_batch_report_html(f, p->title, p->m, p->t, p->thumbs, p->contact_tiles);
    if (fclose(f) != 0 || rc != 0) {
        snprintf(err, err_size, "report.html: write failed");
        return -1;
    }
    return 0;
}

/* Item n's thumbnail into thumbs/<n>.png and tile n of the sheet. */
static void thumbnail(const char *dir, int dfd, size_t n, const lpv_manifest_item *it, lpv_batch_contact *sheet,
                      lpv_batch_report_thumb *th, FILE *warnings)
{
    char src[PATH_SIZE], name[64], err[sizeof th->note];
    const char *image = lpv_batch_image_output(it->line);
    if (!image) {
        snprintf(th->note, sizeof th->note, "no PNG or EXR image output");
    } else if (path_in(src, dir, image, th->note, sizeof th->note) == 0) {
        lpv_batch_thumb t;
        if (lpv_batch_thumb_make(src, &t, err, sizeof err) != 0) {
            snprintf(th->note, sizeof th->note, "%s", err);
        } else {
            snprintf(name, sizeof name, "thumbs/%zu.png", n);
            if (lpv_write_beneath(dfd, name, write_thumb, &t, err, sizeof err) != 0) {
                snprintf(th->note, sizeof th->note, "%s", err);
            } else {
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

int lpv_batch_report(const char *dir, lpv_batch_report_summary *summary, FILE *warnings, char *err,
                     size_t err_size)
{
    lpv_manifest m;
    lpv_batch_totals t = {0};
    lpv_batch_contact sheet = {0};
    lpv_batch_report_thumb *thumbs = NULL;
    int dfd = -1;
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
    if ((dfd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC)) < 0) {
        snprintf(err, err_size, "%s: %s", dir, strerror(errno));
        goto done;
    }
    const int thumbs_fd = lpv_dir_make_beneath(dfd, "thumbs");
    if (thumbs_fd < 0) {
        snprintf(err, err_size, "%s/thumbs: %s%s", dir, strerror(errno),
                 errno == ELOOP || errno == ENOTDIR ? " (a symbolic link or a file; the report writes no thumbnail "
                                                      "through one)"
                                                    : "");
        goto done;
    }
    close(thumbs_fd);
    if (m.count && lpv_batch_contact_init(&sheet, m.count, err, err_size) != 0)
        goto done;
    for (size_t i = 0; i < m.count; i++) {
        if (lpv_manifest_item_ok(&m.items[i]))
            thumbnail(dir, dfd, i, &m.items[i], &sheet, &thumbs[i], warnings);
        else
            lpv_batch_contact_put_failed(&sheet, i);
    }
    if (m.count) {
        if (lpv_write_beneath(dfd, "contact.png", write_contact, &sheet, err, err_size) != 0)
            goto done;
    } else if (unlinkat(dfd, "contact.png", 0) != 0 && errno != ENOENT) { /* an earlier report's would mislead */
        snprintf(err, err_size, "%s/contact.png: %s", dir, strerror(errno));
        goto done;
    }
    const char *title = strrchr(dir, '/');
    page pg = {.title = title && title[1] ? title + 1 : dir, .m = &m, .t = &t, .thumbs = thumbs,
               .contact_tiles = sheet.tiles};
    if (lpv_write_beneath(dfd, "report.html", write_page, &pg, err, err_size) != 0)
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
    if (dfd >= 0)
        close(dfd);
    free(thumbs);
    lpv_batch_contact_free(&sheet);
    lpv_batch_totals_free(&t);
    lpv_manifest_free(&m);
    return rc;
}
