/* report_fixture_main.c - `report_fixture DIR`: writes the batch job folder
 * of report_fixture.h into DIR (created if missing), for report_browser.py. */
#include "report_fixture.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: report_fixture DIR\n");
        return 2;
    }
    if (mkdir(argv[1], 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "report_fixture: %s: %s\n", argv[1], strerror(errno));
        return 1;
    }
    char err[1024] = "";
    if (lpvt_report_fixture(argv[1], err, sizeof err) != 0) {
        fprintf(stderr, "report_fixture: %s\n", err);
        return 1;
    }
    return 0;
}
