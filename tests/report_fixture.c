/* report_fixture.c - the batch job folder the report's tests read
 * (report_fixture.h). */
#include "report_fixture.h"

#include "image_io.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static const char SHARD0[] =
    "{\"id\": \"cornell/cam0/a&b<1>\", \"index\": 0, \"scene\": \"scenes/cornell.glb\", "
    "\"camera\": {\"position\": [0, 1, 3], \"target\": [0, 1, 0]}, \"time\": null, "
    "\"settings\": {\"grid\": 16, \"technique\": \"iv\", \"bounces\": 2, \"exposure\": 0.1}, "
    "\"outputs\": [{\"kind\": \"image\", \"path\": \"images/a.png\"}], \"status\": \"ok\", "
    "\"ms\": {\"load\": 10, \"tick\": 60, \"render\": 20, \"write\": 10, \"total\": 100}, "
    "\"stages\": {\"inject\": 1, \"propagate\": 5}, "
    "\"started\": \"2026-11-25T15:20:00.000Z\", \"finished\": \"2026-11-25T15:20:00.100Z\", \"shard\": [0, 2]}\n"
    "{\"id\": \"blinds/\\\"cam1\\\"\", \"index\": 1, \"scene\": \"scenes/blinds.glb\", \"camera\": null, "
    "\"time\": 2.5, \"settings\": {\"grid\": 32}, \"outputs\": [], \"status\": \"failed\", \"error\": \"timeout\", "
    "\"ms\": {\"load\": 20, \"total\": 999}, \"stages\": {\"inject\": 50}, "
    "\"started\": \"2026-11-25T15:20:10.000Z\", \"finished\": \"2026-11-25T15:20:11.000Z\", \"shard\": [0, 2]}\n"
    "{\"id\": \"blinds/\\\"cam1\\\"\", \"index\": 1, \"scene\": \"scenes/blinds.glb\", \"camera\": null, "
    "\"time\": 2.5, \"settings\": {\"grid\": 32, \"cascades\": [1, 2]}, "
    "\"outputs\": [{\"kind\": \"volume\", \"path\": \"volumes/b.lpvv\"}, "
    "{\"kind\": \"exr\", \"path\": \"images/b.exr\"}], "
    "\"status\": \"ok\", \"ms\": {\"load\": 20, \"tick\": 200, \"render\": 50, \"write\": 30, \"total\": 300}, "
    "\"stages\": {\"inject\": 2, \"propagate\": 10}, "
    "\"started\": \"2026-11-25T15:20:30.000Z\", \"finished\": \"2026-11-25T15:20:36.000Z\", \"shard\": [0, 2]}\n";

static const char SHARD1[] =
    "{\"id\": \"courtyard/cam0/fast\", \"index\": 2, \"scene\": \"scenes/courtyard.glb\", \"time\": null, "
    "\"settings\": {\"technique\": \"lpv\"}, \"outputs\": [], \"status\": \"failed\", "
    "\"error\": \"shader <script>alert(\\\"x\\\")</script> & \\\"quoted\\\"\", "
    "\"ms\": {\"load\": 5, \"total\": 50}, \"stages\": {\"inject\": 2}, "
    "\"started\": \"2026-11-25T15:20:05.000Z\", \"finished\": \"2026-11-25T15:20:05.050Z\", \"shard\": [1, 2]}\n"
    "{\"id\": \"torn/item\", \"index\": 3, \"sta";

static int write_text(const char *dir, const char *name, const char *text, char *err, size_t err_size)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    if (!f || fputs(text, f) < 0 || fclose(f) != 0) {
        snprintf(err, err_size, "%s: %s", path, strerror(errno));
        return -1;
    }
    return 0;
}

int lpvt_report_fixture(const char *dir, char *err, size_t err_size)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/images", dir);
    if (mkdir(path, 0777) != 0 && errno != EEXIST) {
        snprintf(err, err_size, "%s: %s", path, strerror(errno));
        return -1;
    }

    enum { AW = 600, AH = 300, BW = 40, BH = 30 };
    uint8_t *a = malloc((size_t)AW * AH * 4);
    float *b = malloc((size_t)BW * BH * 4 * sizeof *b);
    int rc = -1;
    if (!a || !b) {
        snprintf(err, err_size, "out of memory");
        goto done;
    }
    for (int y = 0; y < AH; y++)
        for (int x = 0; x < AW; x++) {
            uint8_t *p = a + ((size_t)y * AW + (size_t)x) * 4;
            p[0] = (uint8_t)(255 * x / (AW - 1));
            p[1] = (uint8_t)(255 * y / (AH - 1));
            p[2] = (uint8_t)(((x / 50) + (y / 50)) % 2 ? 200 : 40);
            p[3] = 255;
        }
    for (int y = 0; y < BH; y++)
        for (int x = 0; x < BW; x++) {
            float *p = b + ((size_t)y * BW + (size_t)x) * 4;
            const int covered = x >= BW / 4;
            p[0] = covered ? 0.002f * (float)x : 0.0f; /* W/(m^2 sr) */
            p[1] = covered ? 0.001f * (float)y : 0.0f;
            p[2] = covered ? 0.03f : 0.0f;
            p[3] = covered ? 1.0f : 0.0f;
        }
    snprintf(path, sizeof path, "%s/images/a.png", dir);
    if (lpv_image_write_u8(path, AW, AH, 4, a, err, err_size) != 0)
        goto done;
    snprintf(path, sizeof path, "%s/images/b.exr", dir);
    if (lpv_image_write_f32(path, BW, BH, 4, b, err, err_size) != 0)
        goto done;
    if (write_text(dir, "manifest-0-of-2.jsonl", SHARD0, err, err_size) != 0 ||
        write_text(dir, "manifest-1-of-2.jsonl", SHARD1, err, err_size) != 0)
        goto done;
    rc = 0;
done:
    free(a);
    free(b);
    return rc;
}
