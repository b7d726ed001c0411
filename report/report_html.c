/* report_html.c - report.html of a batch job (report_html.h). */
#include "report_html.h"

#include "thumbs.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char STYLE[] =
    "body{font:14px/1.4 system-ui,sans-serif;margin:1.5em;color:#1c1c1c;background:#fafafa}\n"
    "h1{font-size:1.4em;margin:0 0 .6em}h2{font-size:1.1em;margin:1.4em 0 .4em}\n"
    ".counts{display:flex;gap:1em;margin-bottom:.8em}\n"
    ".count{font-size:1.5em;font-weight:600;padding:.2em .6em;border-radius:6px;background:#e8e8e8}\n"
    ".count.ok{background:#d9f0dc;color:#14521d}.count.failed{background:#f6d5d5;color:#7a1010}\n"
    "table{border-collapse:collapse}\n"
    ".figures th{text-align:left;font-weight:500;padding:.15em 1em .15em 0}\n"
    ".figures td{padding:.15em 1em .15em 0}.note{color:#666}\n"
    ".share{width:12em}.bar{display:inline-block;height:.8em;background:#5b7fbf;vertical-align:middle}\n"
    ".items{margin-top:1em;width:100%}\n"
    ".items th{text-align:left;border-bottom:2px solid #999;padding:.3em .5em;position:sticky;top:0;"
    "background:#fafafa}\n"
    ".items td{border-bottom:1px solid #ddd;padding:.3em .5em;vertical-align:top}\n"
    ".items td.num{text-align:right;white-space:nowrap}\n"
    "td.pic{width:260px;text-align:center;background:#282828}\n"
    "img.thumb{max-width:256px;max-height:256px;display:block;margin:auto}\n"
    ".nothumb{color:#ccc;font-size:.9em;padding:1em .5em;word-break:break-word}\n"
    "td.pic.broken{outline:3px solid #c00}\n"
    "tr.failed td{background:#fbeaea}tr.failed td.pic{background:#6e1414}\n"
    ".badge{font-weight:600;padding:.1em .5em;border-radius:4px}\n"
    ".badge.ok{background:#d9f0dc;color:#14521d}.badge.failed{background:#c62828;color:#fff}\n"
    ".error{color:#7a1010;margin-top:.4em;white-space:pre-wrap;word-break:break-word;font-family:monospace}\n"
    ".settings code{display:inline-block;margin:0 .4em .2em 0;background:#eee;padding:0 .3em}\n"
    "ul.outputs{margin:.3em 0 0;padding-left:1.2em;font-size:.9em}\n"
    "body.failed-only tr.ok{display:none}\n";

static const char SCRIPT[] =
    "(function () {\n"
    "  function check() {\n"
    "    var imgs = document.querySelectorAll('img.thumb'), loaded = 0, broken = 0;\n"
    "    for (var i = 0; i < imgs.length; i++) {\n"
    "      if (imgs[i].complete && imgs[i].naturalWidth > 0) {\n"
    "        loaded++;\n"
    "      } else {\n"
    "        broken++;\n"
    "        var cell = imgs[i].closest('td');\n"
    "        if (cell) cell.classList.add('broken');\n"
    "      }\n"
    "    }\n"
    "    document.body.setAttribute('data-thumbs-loaded', String(loaded));\n"
    "    document.body.setAttribute('data-thumbs-broken', String(broken));\n"
    "    document.body.setAttribute('data-thumbs-checked', '1');\n"
    "    var s = document.getElementById('thumbs-status');\n"
    "    if (s) s.textContent = loaded + ' thumbnails shown' + (broken ? ', ' + broken + ' failed to load' : '');\n"
    "  }\n"
    "  window.addEventListener('load', check);\n"
    "  var box = document.getElementById('failed-only');\n"
    "  if (box) box.addEventListener('change', function () {\n"
    "    document.body.classList.toggle('failed-only', box.checked);\n"
    "  });\n"
    "})();\n";

/* s for HTML text and attribute values. */
static void esc(FILE *f, const char *s)
{
    for (; s && *s; s++) {
        switch (*s) {
        case '&': fputs("&amp;", f); break;
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '"': fputs("&quot;", f); break;
        case '\'': fputs("&#39;", f); break;
        default: fputc(*s, f);
        }
    }
}

/* A relative path for href/src: every byte but unreserved ones and '/'
 * percent-encoded (so "a:b" cannot become a scheme), which needs no HTML
 * escape after. */
static void url(FILE *f, const char *s)
{
    for (; s && *s; s++) {
        unsigned char c = (unsigned char)*s;
        if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '.' ||
            c == '_' || c == '~' || c == '/')
            fputc(c, f);
        else
            fprintf(f, "%%%02X", c);
    }
}

/* A JSON value as text: strings as they are, anything else as compact JSON
 * (reals to 12 digits, so 0.1 shows as 0.1). */
static void value(FILE *f, json_t *v)
{
    if (json_is_string(v)) {
        esc(f, json_string_value(v));
        return;
    }
    char *s = json_dumps(v, JSON_ENCODE_ANY | JSON_COMPACT | JSON_REAL_PRECISION(12));
    esc(f, s ? s : "?");
    free(s);
}

static void duration(FILE *f, double s)
{
    if (isnan(s))
        fputs("unknown", f);
    else if (s < 60.0)
        fprintf(f, "%.1f s", s);
    else if (s < 3600.0)
        fprintf(f, "%d min %04.1f s", (int)(s / 60.0), fmod(s, 60.0));
    else
        fprintf(f, "%d h %02d min %02d s", (int)(s / 3600.0), (int)fmod(s / 60.0, 60.0), (int)fmod(s, 60.0));
}

static void plural(FILE *f, long n, const char *one, const char *many)
{
    fprintf(f, "%ld %s", n, n == 1 ? one : many);
}

static void sums_table(FILE *f, const char *heading, const char *what, const lpv_batch_sum *sums, size_t n,
                       double total)
{
    if (n == 0)
        return;
    fprintf(f, "<h2>%s</h2>\n<p class=\"note\">%s</p>\n", heading, what);
    fputs("<table class=\"figures\">\n<tr><th>name</th><th>ms</th><th>share</th><th class=\"share\"></th></tr>\n", f);
    for (size_t i = 0; i < n; i++) {
        double share = total > 0.0 ? 100.0 * sums[i].ms / total : 0.0;
        fputs("<tr><th>", f);
        esc(f, sums[i].name);
        fprintf(f, "</th><td class=\"num\">%.1f</td><td class=\"num\">%.1f %%</td>"
                   "<td class=\"share\"><span class=\"bar\" style=\"width:%.1f%%\"></span></td></tr>\n",
                sums[i].ms, share, share);
    }
    fprintf(f, "<tr><th>all</th><td class=\"num\">%.1f</td><td class=\"num\">100.0 %%</td><td></td></tr>\n", total);
    fputs("</table>\n", f);
}

static void totals(FILE *f, const lpv_manifest *m, const lpv_batch_totals *t, const lpv_batch_report_thumb *thumbs,
                   size_t contact_tiles)
{
    fputs("<section class=\"totals\">\n<div class=\"counts\"><span class=\"count ok\">", f);
    fprintf(f, "%ld ok</span><span class=\"count failed\">%ld failed</span><span class=\"count\">", t->ok,
            t->failed);
    plural(f, t->items, "item", "items");
    fputs("</span></div>\n<table class=\"figures\">\n", f);
    fputs("<tr><th>images per hour</th><td>", f);
    if (isnan(t->images_per_hour))
        fputs("unknown", f);
    else
        fprintf(f, "%.1f", t->images_per_hour);
    fputs("</td><td class=\"note\">ok items per hour of wall time</td></tr>\n<tr><th>wall time</th><td>", f);
    duration(f, t->span_s);
    fputs("</td><td class=\"note\">from the earliest start to the latest finish of any manifest line</td></tr>\n", f);
    fputs("<tr><th>mean time per item</th><td>", f);
    if (isnan(t->mean_ms))
        fputs("unknown", f);
    else
        fprintf(f, "%.1f ms", t->mean_ms);
    fputs("</td><td class=\"note\">", f);
    fprintf(f, "ms.total of %ld ", t->item_ms_count);
    fputs(t->item_ms_count == 1 ? "item" : "items", f);
    fputs(", summed: ", f);
    duration(f, t->item_ms / 1000.0);
    fputs("</td></tr>\n</table>\n", f);

    sums_table(f, "Time per stage", "GPU time of each engine stage (the manifests' \"stages\"), summed over the items",
               t->stages, t->nstages, t->stages_ms);
    sums_table(f, "Time per phase", "Wall-clock time of each phase of an item (the manifests' \"ms\" but total), "
               "summed over the items", t->phases, t->nphases, t->phases_ms);

    long without = 0;
    for (size_t i = 0; i < m->count; i++)
        if (lpv_manifest_item_ok(&m->items[i]) && !thumbs[i].made)
            without++;
    fputs("<h2>Manifests</h2>\n<p>", f);
    for (size_t i = 0; i < m->nfiles; i++) {
        fputs(i ? ", <code>" : "<code>", f);
        esc(f, m->files[i]);
        fputs("</code>", f);
    }
    fputs(": ", f);
    plural(f, m->lines, "line", "lines");
    if (m->skipped) {
        fputs(", <strong class=\"skipped\">", f);
        plural(f, m->skipped, "line", "lines");
        fputs(" skipped</strong> (not a JSON object with an id)", f);
    }
    if (m->superseded) {
        fputs(", ", f);
        plural(f, m->superseded, "line", "lines");
        fputs(" superseded by a later line of the same id", f);
    }
    fputs(".", f);
    if (without) {
        fputs(" <strong>", f);
        plural(f, without, "ok item has", "ok items have");
        fputs(" no thumbnail</strong>.", f);
    }
    fputs("</p>\n<p>", f);
    if (contact_tiles) {
        fputs("<a href=\"contact.png\">Contact sheet</a>", f);
        if (contact_tiles < m->count)
            fprintf(f, " (the first %zu items)", contact_tiles);
        fputs(". ", f);
    }
    fputs("<label><input type=\"checkbox\" id=\"failed-only\"> failed items only</label> "
          "<span id=\"thumbs-status\" class=\"note\"></span></p>\n</section>\n",
          f);
}

static void row(FILE *f, size_t n, const lpv_manifest_item *it, const lpv_batch_report_thumb *th)
{
    const int ok = lpv_manifest_item_ok(it);
    json_t *line = it->line;
    fprintf(f, "<tr class=\"item %s\" id=\"item-%zu\"><td class=\"num\">%zu</td><td class=\"pic\">",
            ok ? "ok" : "failed", n, n);
    const char *image = lpv_batch_image_output(line);
    if (th->made) {
        if (image) {
            fputs("<a href=\"", f);
            url(f, image);
            fputs("\">", f);
        }
        fprintf(f, "<img class=\"thumb\" src=\"thumbs/%zu.png\" width=\"%d\" height=\"%d\" alt=\"", n, th->width,
                th->height);
        esc(f, it->id);
        fputs(image ? "\"></a>" : "\">", f);
    } else {
        fputs("<div class=\"nothumb\">", f);
        esc(f, ok ? th->note : "failed");
        fputs("</div>", f);
    }
    fputs("</td>\n<td class=\"id\"><code>", f);
    esc(f, it->id);
    fputs("</code>", f);
    json_t *outputs = json_object_get(line, "outputs");
    if (json_array_size(outputs)) {
        fputs("<ul class=\"outputs\">", f);
        size_t i;
        json_t *o;
        json_array_foreach(outputs, i, o)
        {
            const char *kind = json_string_value(json_object_get(o, "kind"));
            const char *path = json_string_value(json_object_get(o, "path"));
            if (!path)
                continue;
            fputs("<li>", f);
            esc(f, kind ? kind : "output");
            fputs(": <a href=\"", f);
            url(f, path);
            fputs("\">", f);
            esc(f, path);
            fputs("</a></li>", f);
        }
        fputs("</ul>", f);
    }
    fputs("</td>\n<td class=\"scene\">", f);
    json_t *scene = json_object_get(line, "scene");
    if (scene && !json_is_null(scene))
        value(f, scene);
    else
        fputs("built-in", f);
    fputs("</td>\n<td class=\"settings\">", f);
    const char *key;
    json_t *v;
    json_object_foreach(json_object_get(line, "settings"), key, v)
    {
        fputs("<code>", f);
        esc(f, key);
        fputc('=', f);
        value(f, v);
        fputs("</code> ", f);
    }
    fputs("</td>\n<td class=\"num\">", f);
    json_t *time = json_object_get(line, "time");
    if (json_is_number(time))
        fprintf(f, "%g s", json_number_value(time));
    else
        fputs("&ndash;", f);
    fputs("</td><td class=\"num\">", f);
    json_t *total = json_object_get(json_object_get(line, "ms"), "total");
    if (json_is_number(total))
        fprintf(f, "%.1f", json_number_value(total));
    else
        fputs("&ndash;", f);
    fputs("</td>\n<td class=\"status\">", f);
    if (ok) {
        fputs("<span class=\"badge ok\">ok</span>", f);
    } else {
        const char *status = json_string_value(json_object_get(line, "status"));
        const char *error = json_string_value(json_object_get(line, "error"));
        fputs("<span class=\"badge failed\">failed</span>", f);
        if (status && strcmp(status, "failed") != 0) {
            fputs(" <span class=\"note\">status ", f);
            esc(f, status);
            fputs("</span>", f);
        }
        fputs("<div class=\"error\">", f);
        esc(f, error ? error : "(no error message)");
        fputs("</div>", f);
    }
    fputs("</td></tr>\n", f);
}

int lpv_batch_report_html(FILE *f, const char *title, const lpv_manifest *m, const lpv_batch_totals *t,
                          const lpv_batch_report_thumb *thumbs, size_t contact_tiles)
{
    fputs("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n", f);
    fputs("<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>Batch report: ", f);
    esc(f, title);
    fprintf(f, "</title>\n<style>\n%s</style>\n</head>\n<body>\n<h1>Batch report: ", STYLE);
    esc(f, title);
    fputs("</h1>\n", f);
    totals(f, m, t, thumbs, contact_tiles);
    if (m->count == 0) {
        fputs("<p><strong>No items:</strong> the manifests hold no line with an id.</p>\n", f);
    } else {
        fputs("<table class=\"items\">\n<thead><tr><th>#</th><th>image</th><th>id and outputs</th><th>scene</th>"
              "<th>settings</th><th>time</th><th>ms</th><th>status</th></tr></thead>\n<tbody>\n",
              f);
        for (size_t i = 0; i < m->count; i++)
            row(f, i, &m->items[i], &thumbs[i]);
        fputs("</tbody>\n</table>\n", f);
    }
    fprintf(f, "<script>\n%s</script>\n</body>\n</html>\n", SCRIPT);
    return ferror(f) ? -1 : 0;
}
