/*
 * settings_switch.h - the tri-state switch of every on/off knob, core's and
 * each technique's (techniques/NAME/core/NAME_settings.h).
 */
#ifndef LPV_SETTINGS_SWITCH_H
#define LPV_SETTINGS_SWITCH_H

/* Tri-state switch: 0 means "the default". */
typedef enum lpv_switch {
    LPV_SWITCH_DEFAULT = 0,
    LPV_SWITCH_ON = 1,
    LPV_SWITCH_OFF = 2,
} lpv_switch;

#endif
