/* argil-board's configuration: defaults, an INI file and command-line overrides, all through
 * one table of settings (section.key), so the file, the CLI and --help say the same thing.
 * Library code: returns which rule the input broke; never prints, never exits. */
#ifndef ARGIL_BOARD_CONFIG_H
#define ARGIL_BOARD_CONFIG_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "firmware/hal/gpio_port.h"
#include "shared/argil_err.h"

#define BOARD_CFG_STR 128u

typedef enum { BOARD_BUS_SOCKETCAN = 0, BOARD_BUS_SIM = 1 } board_bus_t;
typedef enum { BOARD_LINK_UDP = 0, BOARD_LINK_FFS = 1 } board_link_t;

typedef struct {
    board_bus_t bus;
    char can_if[32];
    uint32_t drive_heartbeat_ms;     /* heartbeat consumer time per drive */
    uint32_t bus_recovery_ms;        /* bus-off must recover within this, else exit */
    gpio_names_t gpio;
    board_link_t link;
    char link_target[BOARD_CFG_STR]; /* "ADDR:PORT" or the FunctionFS mount directory */
    char link_key[BOARD_CFG_STR];    /* UDP link key file; "" = none (docs/link.md "Link key") */
    bool link_insecure;              /* UDP without a key may arm (explicit, logged) */
    uint32_t host_timeout_ms;
    uint32_t host_fade_ms;
    uint32_t rate_hz;                /* 1000, 2000 or 4000 (100 … 10000 accepted) */
    int32_t rt_priority;             /* SCHED_FIFO 1..99; 0 = stay SCHED_OTHER */
    int32_t link_rt_priority;        /* the link thread(s): 1..99; 0 = rt_priority − 10 */
    int32_t cpu;                     /* CPU to pin the fast loop to; -1 = any */
    uint32_t overrun_streak;         /* consecutive overruns that are a fault; 0 = never */
    float max_force_n;
    float max_velocity_m_s;
    float model_scale;               /* device → model until the host's TOOL frame sets one */
    float model_offset_m[3];
    uint32_t stats_period_s;         /* deadline statistics to the log; 0 = only on exit */
    float duration_s;                /* run this long then stop cleanly; 0 = until signalled */
} board_daemon_cfg_t;

/* One setting: where it lives in the INI file, its CLI flag and what --help says. */
typedef struct {
    const char *section;
    const char *key;
    const char *flag;                /* long option without "--" */
    const char *arg;                 /* argument name for --help; NULL: a flag (--NAME alone is
                                      * "yes"; in the file: yes or no) */
    const char *help;
} board_setting_t;

extern const board_setting_t board_settings[];
extern const size_t board_settings_count;

void board_config_default(board_daemon_cfg_t *c);

/* The rule a setting, an INI text or the settings together broke; BOARD_CONFIG_OK = 0. */
typedef enum {
    BOARD_CONFIG_OK = 0,
    BOARD_CONFIG_ERR_UNKNOWN = -1,       /* no setting section.key */
    BOARD_CONFIG_ERR_VALUE = -2,         /* a value malformed or outside its setting's range */
    BOARD_CONFIG_ERR_NUL = -3,           /* a NUL byte in the text */
    BOARD_CONFIG_ERR_LINE_LONG = -4,     /* a line over libinih's 197 characters */
    BOARD_CONFIG_ERR_AFTER_SECTION = -5, /* text after a section's ']' */
    BOARD_CONFIG_ERR_NO_SECTION = -6,    /* a key outside any [section] */
    BOARD_CONFIG_ERR_SECTION = -7,       /* a '[' line without its ']' */
    BOARD_CONFIG_ERR_NO_VALUE = -8,      /* a line that is neither key = value nor a [section] */
    BOARD_CONFIG_ERR_READER = -9,        /* libinih failed otherwise (its memory) */
    BOARD_CONFIG_ERR_KEY_INSECURE = -10, /* link.key and link.insecure together */
    BOARD_CONFIG_ERR_USB_KEY = -11,      /* link.key or link.insecure on a FunctionFS link */
    BOARD_CONFIG_ERR_FADE = -12,         /* link.fade_ms above ten host timeouts */
    BOARD_CONFIG_ERR_HEARTBEAT = -13     /* can.heartbeat_timeout_ms shorter than one tick */
} board_config_err_t;

/* The argil_err_t a command reports for e: a setting that does not exist or settings that do not
 * go together ARGIL_ERR_ARG, every other rule ARGIL_ERR_PARSE. */
argil_err_t board_config_err_argil(board_config_err_t e);

/* Sets section.key from text. BOARD_CONFIG_ERR_UNKNOWN for an unknown setting, _VALUE for a
 * value that is malformed or out of range; why gets one line saying which. */
board_config_err_t board_config_set(board_daemon_cfg_t *c, const char *section, const char *key,
                                    const char *value, char *why, size_t why_len);

/* Applies INI text of len bytes (no NUL needed) through libinih: [section] headers, key = value
 * or key: value, ';' or '#' comments at the start of a line, ';' after a blank inline, blank
 * lines, a UTF-8 byte-order mark. Refused besides: a NUL byte, a line over libinih's 197
 * characters, text after a section's ']', a key outside any [section], an unknown setting, a
 * bad value; an indented line is a line of its own, never a continuation. On error *line is
 * the 1-based line, why says what is wrong and *c is unchanged. */
board_config_err_t board_config_parse_ini(board_daemon_cfg_t *c, const char *text, size_t len,
                                          uint32_t *line, char *why, size_t why_len);

/* Checks the settings together (keys, fade, heartbeat against the rate); one line into why. */
board_config_err_t board_config_check(const board_daemon_cfg_t *c, char *why, size_t why_len);

#endif
