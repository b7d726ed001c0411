/*
 * test_open_beneath.c - core/open_beneath.h: both the openat2 path and the
 * component walk refuse absolute paths, "..", and symbolic links anywhere on
 * the way, and open plain files and folders; under a thread that swaps a
 * file for a link to a file outside, neither ever opens the outside file
 * (issue 14, item 5: the daemon's check-then-open let 29 of 3000 through).
 */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

#include "open_beneath.h"
#include "test_util.h"

typedef int (*open_fn)(int, const char *, int);

static char root[512], outside[512];

static void put(const char *dir, const char *name, const char *text)
{
    char p[1024];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    FILE *f = fopen(p, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

/* The first byte of what fn opens at rel beneath root, or -errno. */
static int first_byte(open_fn fn, int rootfd, const char *rel)
{
    int fd = fn(rootfd, rel, O_RDONLY);
    if (fd < 0)
        return -errno;
    char c = 0;
    ssize_t n = read(fd, &c, 1);
    close(fd);
    return n == 1 ? c : -EIO;
}

static void setup_tree(void)
{
    snprintf(root, sizeof root, "%s/beneath-root", lpvt_tmpdir());
    snprintf(outside, sizeof outside, "%s/beneath-outside", lpvt_tmpdir());
    mkdir(root, 0700);
    mkdir(outside, 0700);
    char p[1024], q[1024];
    snprintf(p, sizeof p, "%s/sub", root);
    mkdir(p, 0700);
    put(root, "in.txt", "I");
    put(p, "deep.txt", "D");
    put(outside, "secret.txt", "S");
    snprintf(p, sizeof p, "%s/link.txt", root);
    unlink(p);
    snprintf(q, sizeof q, "%s/secret.txt", outside);
    assert_int_equal(symlink(q, p), 0);
    snprintf(p, sizeof p, "%s/inlink.txt", root);
    unlink(p);
    assert_int_equal(symlink("in.txt", p), 0);
    snprintf(p, sizeof p, "%s/dirlink", root);
    unlink(p);
    assert_int_equal(symlink(outside, p), 0);
}

static void check_contract(open_fn fn)
{
    int rootfd = open(root, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    assert_true(rootfd >= 0);
    assert_int_equal(first_byte(fn, rootfd, "in.txt"), 'I');
    assert_int_equal(first_byte(fn, rootfd, "sub/deep.txt"), 'D');
    assert_int_equal(first_byte(fn, rootfd, "./sub//deep.txt"), 'D');
    assert_int_equal(first_byte(fn, rootfd, "/etc/hostname"), -EXDEV);
    assert_int_equal(first_byte(fn, rootfd, "../beneath-outside/secret.txt"), -EXDEV);
    assert_int_equal(first_byte(fn, rootfd, "sub/../in.txt"), -EXDEV);
    assert_int_equal(first_byte(fn, rootfd, "link.txt"), -ELOOP);
    assert_int_equal(first_byte(fn, rootfd, "inlink.txt"), -ELOOP); /* links inside are refused too */
    assert_int_equal(first_byte(fn, rootfd, "dirlink/secret.txt"), -ELOOP);
    assert_int_equal(first_byte(fn, rootfd, "missing.txt"), -ENOENT);
    assert_int_equal(first_byte(fn, rootfd, "in.txt/x"), -ENOTDIR);
    int d = fn(rootfd, "sub", O_RDONLY | O_DIRECTORY);
    assert_true(d >= 0);
    close(d);
    d = fn(rootfd, ".", O_RDONLY);
    assert_true(d >= 0); /* the folder itself: the caller's fstat says it is not a file */
    struct stat st;
    assert_int_equal(fstat(d, &st), 0);
    assert_true(S_ISDIR(st.st_mode));
    close(d);
    close(rootfd);
}

static void test_contract_openat2(void **state)
{
    (void)state;
    setup_tree();
    check_contract(lpv_open_beneath);
}

static void test_contract_walk(void **state)
{
    (void)state;
    setup_tree();
    check_contract(lpv_open_beneath_walk);
}

static volatile int stop_swapping;

/* race.txt under the root: the plain file, then a link to the outside file, and again, by atomic renames. */
static void *swapper(void *arg)
{
    (void)arg;
    char race[1024], tl[1024], tf[1024], in[1024], secret[1024];
    snprintf(race, sizeof race, "%s/race.txt", root);
    snprintf(tl, sizeof tl, "%s/.race-l", root);
    snprintf(tf, sizeof tf, "%s/.race-f", root);
    snprintf(in, sizeof in, "%s/in.txt", root);
    snprintf(secret, sizeof secret, "%s/secret.txt", outside);
    while (!stop_swapping) {
        unlink(tl);
        unlink(tf);
        if (symlink(secret, tl) == 0)
            rename(tl, race);
        if (link(in, tf) == 0)
            rename(tf, race);
    }
    return NULL;
}

static void race(open_fn fn)
{
    setup_tree();
    char race_p[1024], in[1024];
    snprintf(race_p, sizeof race_p, "%s/race.txt", root);
    snprintf(in, sizeof in, "%s/in.txt", root);
    unlink(race_p);
    assert_int_equal(link(in, race_p), 0);
    int rootfd = open(root, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    assert_true(rootfd >= 0);
    stop_swapping = 0;
    pthread_t t;
    assert_int_equal(pthread_create(&t, NULL, swapper, NULL), 0);
    int seen_in = 0, refused = 0, leaked = 0;
    for (int i = 0; i < 20000; ++i) {
        int b = first_byte(fn, rootfd, "race.txt");
        seen_in += b == 'I';
        refused += b == -ELOOP;
        leaked += b == 'S';
    }
    stop_swapping = 1;
    pthread_join(t, NULL);
    close(rootfd);
    printf("    race: %d plain, %d refused links, %d outside\n", seen_in, refused, leaked);
    assert_int_equal(leaked, 0);
    assert_true(seen_in > 0);
}

static void test_race_openat2(void **state)
{
    (void)state;
    race(lpv_open_beneath);
}

static void test_race_walk(void **state)
{
    (void)state;
    race(lpv_open_beneath_walk);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_contract_openat2),
        cmocka_unit_test(test_contract_walk),
        cmocka_unit_test(test_race_openat2),
        cmocka_unit_test(test_race_walk),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
