/*
 * proto_types.c - the message types of the wire protocol v1 (SPEC sections
 * 2 and 3.1): their names for messages and logs, and which are requests and
 * which are answered by a reply (ACK is not). See proto.h.
 */
#include "proto.h"

/* ---- Names ---------------------------------------------------------------- */

static const char *const request_names[] = {
    NULL,           "HELLO",     "SCENE_LOAD",   "SCENE_UPDATE", "LIGHT_SET",
    "LIGHT_REMOVE", "CAMERA_SET", "CONFIG",      "TICK",         "SUBSCRIBE",
    "UNSUBSCRIBE",  "GET_VOLUME", "GET_FRAME",   "QUERY_IRRADIANCE", "STATS",
    "BYE",          "ACK",
};

static const char *const reply_names[] = {
    NULL,                 "HELLO_REPLY",       "SCENE_LOAD_REPLY",  "SCENE_UPDATE_REPLY",
    "LIGHT_SET_REPLY",    "LIGHT_REMOVE_REPLY", "CAMERA_SET_REPLY", "CONFIG_REPLY",
    "TICK_REPLY",         "SUBSCRIBE_REPLY",   "UNSUBSCRIBE_REPLY", "GET_VOLUME_REPLY",
    "GET_FRAME_REPLY",    "QUERY_IRRADIANCE_REPLY", "STATS_REPLY", "BYE_REPLY",
    "ACK_REPLY",
};

const char *lpvp_type_name(uint16_t type)
{
    if (type >= LPVP_HELLO && type <= LPVP_ACK)
        return request_names[type];
    if (type == LPVP_VOLUME)
        return "VOLUME";
    if (type == LPVP_FRAME)
        return "FRAME";
    if (type == LPVP_ERROR)
        return "ERROR";
    /* ACK has no reply (R3.1), so 0x8010 is not a type. */
    if ((type & LPVP_REPLY_BIT) && (type & 0x7FFF) >= LPVP_HELLO && (type & 0x7FFF) < LPVP_ACK)
        return reply_names[type & 0x7FFF];
    return "UNKNOWN";
}

int lpvp_type_is_request(uint16_t type)
{
    return type >= LPVP_HELLO && type <= LPVP_ACK;
}

int lpvp_type_has_reply(uint16_t type)
{
    return lpvp_type_is_request(type) && type != LPVP_ACK;
}
