/*
 * proto_internal.h - what the files of the frame codec share
 * (proto_header.c, proto_parser.c); not part of the library's API (proto.h).
 */
#ifndef LPVP_PROTO_INTERNAL_H
#define LPVP_PROTO_INTERNAL_H

#include "proto.h"

/* *lim, or the defaults when lim is NULL (lpvp_limits_default). */
lpvp_limits lpvp_limits_or_default(const lpvp_limits *lim);

#endif /* LPVP_PROTO_INTERNAL_H */
