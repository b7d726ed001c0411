/*
 * proto_address.c - where the daemon and its clients meet (SPEC R1.1): the
 * default Unix socket path and HOST:PORT splitting, one rule in one place so
 * that the daemon and the C clients always agree. See proto.h.
 */
#include "proto.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* ---- Addresses ------------------------------------------------------------ */

void lpvp_default_socket_path(char *out, size_t n)
{
    const char *xdg = getenv("XDG_RUNTIME_DIR");
    struct stat st;
    if (xdg && xdg[0] == '/' && stat(xdg, &st) == 0 && S_ISDIR(st.st_mode))
        snprintf(out, n, "%s/lpvd.sock", xdg);
    else
        snprintf(out, n, "/tmp/lpvd-%u.sock", (unsigned)getuid());
}

int lpvp_split_host_port(const char *address, char *host, size_t host_n, unsigned *port, char *err, size_t err_n)
{
    const char *s = address;
    const char *colon = strrchr(s, ':');
    const char *port_str = colon ? colon + 1 : s;
    size_t hl = colon ? (size_t)(colon - s) : 0;
    if (hl >= 2 && s[0] == '[' && s[hl - 1] == ']') {
        s += 1;
        hl -= 2;
    }
    if (hl >= host_n) {
        lpvp_set_error(err, err_n, "%s: host name too long", address);
        return -1;
    }
    memcpy(host, s, hl);
    host[hl] = '\0';
    if (!host[0])
        snprintf(host, host_n, "127.0.0.1");
    char *end = NULL;
    unsigned long p = strtoul(port_str, &end, 10);
    if (!port_str[0] || *end || p > 65535 || port_str[0] == '-' || port_str[0] == '+') {
        lpvp_set_error(err, err_n, "%s: expected HOST:PORT or PORT with a port 0..65535", address);
        return -1;
    }
    *port = (unsigned)p;
    return 0;
}
