/* argil-board settings: one table, set from the command line or from INI text read by libinih
 * (Debian's libinih-dev) under argil's rules (board_config.h). */
#include "board_config.h"

#include <errno.h>
#include <ini.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "shared/argil_limits.h"

const board_setting_t board_settings[] = {
    {"can", "bus", "bus", "socketcan|sim",
     "drive bus: the SocketCAN interface, or the simulated arm (no hardware)"},
    {"can", "interface", "can", "IF", "SocketCAN interface of the drives (can0)"},
    {"can", "heartbeat_timeout_ms", "drive-heartbeat-ms", "MS",
     "heartbeat consumer time per drive; drives produce every 100 ms: 2 periods + margin (250)"},
    {"can", "bus_recovery_ms", "bus-recovery-ms", "MS",
     "bus-off must be restarted (restart-ms) within this, else exit for a restart (500)"},
    {"gpio", "chip", "gpio-chip", "CHIP", "GPIO chip: name, path, label or number (gpiochip0)"},
    {"gpio", "estop", "line-estop", "NAME", "e-stop input, active low (ESTOP_N)"},
    {"gpio", "drive_fault", "line-drive-fault", "NAME", "drive fault input, active low (DRIVE_FAULT_N)"},
    {"gpio", "stylus_btn1", "line-btn1", "NAME", "stylus button 1 input (STYLUS_BTN1)"},
    {"gpio", "stylus_btn2", "line-btn2", "NAME", "stylus button 2 input (STYLUS_BTN2)"},
    {"gpio", "drive_enable", "line-drive-enable", "NAME", "drive enable output (DRIVE_ENABLE)"},
    {"gpio", "status_led", "line-led", "NAME", "status LED output, a pattern per state (STATUS_LED)"},
    {"gpio", "wdog_kick", "line-wdog", "NAME",
     "external watchdog output, toggled every healthy tick (WDOG_KICK)"},
    {"link", "host", "link", "udp:ADDR:PORT|ffs:DIR",
     "host link: UDP address to listen on, or a FunctionFS mount (udp:0.0.0.0:7700)"},
    {"link", "heartbeat_timeout_ms", "host-timeout-ms", "MS",
     "host heartbeat silence that stops sculpting and fades the force (50)"},
    {"link", "fade_ms", "host-fade-ms", "MS", "force fade to zero after the host is lost (20)"},
    {"link", "rt_priority", "link-rt-priority", "PRIO",
     "SCHED_FIFO priority of the link thread(s), 1-99, used when the loop is real-time; 0 = 10 "
     "under the loop's (0)"},
    {"link", "key", "key", "FILE",
     "UDP link key file (argil keygen FILE; mode 0600): every datagram carries its tag. With no "
     "key the board refuses to arm over UDP (none)"},
    {"link", "insecure", "insecure", NULL,
     "UDP without a key may arm: anyone who reaches the port may command the arm; logged at "
     "start and in every stats line (file: insecure = yes; default no)"},
    {"loop", "rate_hz", "rate-hz", "HZ", "loop rate: 1000, 2000 or 4000 (1000)"},
    {"loop", "rt_priority", "rt-priority", "PRIO",
     "SCHED_FIFO priority of the fast loop, 1-99; 0 = no real-time scheduling (80)"},
    {"loop", "cpu", "cpu", "N", "CPU to pin the fast loop to; -1 = any (-1)"},
    {"loop", "overrun_streak", "overrun-streak", "N",
     "ticks in a row over their period that are a fault; 0 = never (3)"},
    {"loop", "stats_period_s", "stats-period-s", "S",
     "log deadline statistics every S seconds; 0 = only on exit (10)"},
    {"loop", "duration_s", "duration-s", "S", "stop cleanly after S seconds; 0 = run until signalled (0)"},
    {"limits", "max_force_n", "max-force-n", "N", "hard limit on the force to the hand (3.3)"},
    {"limits", "max_velocity_m_s", "max-velocity-m-s", "M/S",
     "tool speed that is a fault; 0 = no limit (1.5)"},
    {"transform", "scale", "model-scale", "K",
     "device-to-model scale until the host sends its tool transform (1)"},
    {"transform", "offset_m", "model-offset-m", "X,Y,Z",
     "device-to-model offset in metres, same rule (0,0,0)"},
};
const size_t board_settings_count = sizeof(board_settings) / sizeof(board_settings[0]);

static void copy_str(char *dst, size_t cap, const char *src)
{
    const size_t n = strlen(src) < cap - 1u ? strlen(src) : cap - 1u;
    memcpy(dst, src, n);
    dst[n] = '\0';
}

void board_config_default(board_daemon_cfg_t *c)
{
    memset(c, 0, sizeof(*c));
    c->bus = BOARD_BUS_SOCKETCAN;
    copy_str(c->can_if, sizeof(c->can_if), "can0");
    c->drive_heartbeat_ms = ARGIL_DRIVE_HEARTBEAT_CONSUMER_US / 1000u;
    c->bus_recovery_ms = 500;
    gpio_names_default(&c->gpio);
    c->link = BOARD_LINK_UDP;
    copy_str(c->link_target, sizeof(c->link_target), "0.0.0.0:7700");
    c->host_timeout_ms = 50;
    c->host_fade_ms = 20;
    c->rate_hz = 1000;
    c->rt_priority = 80;
    c->cpu = -1;
    c->overrun_streak = 3;
    c->stats_period_s = 10;
    c->duration_s = 0.0f;
    c->max_force_n = 3.3f;
    c->max_velocity_m_s = 1.5f;
    c->model_scale = 1.0f;
}

/* True when v is a whole decimal number lo..hi, stored in *out. */
static bool parse_long(const char *v, long lo, long hi, long *out)
{
    char *end = NULL;
    errno = 0;
    const long x = strtol(v, &end, 10);
    if (errno != 0 || end == v || *end != '\0' || x < lo || x > hi)
        return false;
    *out = x;
    return true;
}

/* True when v is a finite number lo..hi, stored in *out. */
static bool parse_float(const char *v, float lo, float hi, float *out)
{
    char *end = NULL;
    errno = 0;
    const float x = strtof(v, &end);
    if (errno != 0 || end == v || *end != '\0' || !isfinite(x) || x < lo || x > hi)
        return false;
    *out = x;
    return true;
}

/* True when v is a name of 1..cap-1 characters without blanks or control characters, copied
 * into dst. */
static bool set_name(char *dst, size_t cap, const char *v)
{
    if (v[0] == '\0' || strlen(v) >= cap)
        return false;
    for (const char *p = v; *p; p++)
        if (*p == ' ' || *p == '\t' || (unsigned char)*p < 0x20)
            return false;
    copy_str(dst, cap, v);
    return true;
}

argil_err_t board_config_err_argil(board_config_err_t e)
{
    switch (e) {
    case BOARD_CONFIG_OK: return ARGIL_OK;
    case BOARD_CONFIG_ERR_UNKNOWN:
    case BOARD_CONFIG_ERR_KEY_INSECURE:
    case BOARD_CONFIG_ERR_USB_KEY:
    case BOARD_CONFIG_ERR_FADE:
    case BOARD_CONFIG_ERR_HEARTBEAT: return ARGIL_ERR_ARG;
    default: return ARGIL_ERR_PARSE;
    }
}

#define BAD(...) (snprintf(why, why_len, __VA_ARGS__), BOARD_CONFIG_ERR_VALUE)

board_config_err_t board_config_set(board_daemon_cfg_t *c, const char *section, const char *key,
                                    const char *v, char *why, size_t why_len)
{
    long x = 0;
    float f = 0.0f;
    const char *lines[] = {"estop", "drive_fault", "stylus_btn1", "stylus_btn2",
                           "drive_enable", "status_led", "wdog_kick"};
#define IS(s, k) (strcmp(section, s) == 0 && strcmp(key, k) == 0)
    if (IS("can", "bus")) {
        if (strcmp(v, "socketcan") == 0)
            c->bus = BOARD_BUS_SOCKETCAN;
        else if (strcmp(v, "sim") == 0)
            c->bus = BOARD_BUS_SIM;
        else
            return BAD("can.bus '%s': expected socketcan or sim", v);
        return BOARD_CONFIG_OK;
    }
    if (IS("can", "interface")) {
        if (!set_name(c->can_if, 16, v))
            return BAD("can.interface '%s': expected an interface name of 1-15 characters", v);
        return BOARD_CONFIG_OK;
    }
    if (IS("can", "heartbeat_timeout_ms")) {
        if (!parse_long(v, 10, 10000, &x))
            return BAD("can.heartbeat_timeout_ms '%s': expected 10-10000", v);
        c->drive_heartbeat_ms = (uint32_t)x;
        return BOARD_CONFIG_OK;
    }
    if (IS("can", "bus_recovery_ms")) {
        if (!parse_long(v, 10, 60000, &x))
            return BAD("can.bus_recovery_ms '%s': expected 10-60000", v);
        c->bus_recovery_ms = (uint32_t)x;
        return BOARD_CONFIG_OK;
    }
    if (IS("gpio", "chip")) {
        if (!set_name(c->gpio.chip, GPIO_NAME_LEN, v))
            return BAD("gpio.chip '%s': expected a chip name of 1-%u characters", v,
                       GPIO_NAME_LEN - 1u);
        return BOARD_CONFIG_OK;
    }
    if (strcmp(section, "gpio") == 0) {
        for (uint32_t i = 0; i < 7; i++) {
            if (strcmp(key, lines[i]) != 0)
                continue;
            char *dst = i < GPIO_IN_COUNT ? c->gpio.in[i] : c->gpio.out[i - GPIO_IN_COUNT];
            if (!set_name(dst, GPIO_NAME_LEN, v))
                return BAD("gpio.%s '%s': expected a line name of 1-%u characters", key, v,
                           GPIO_NAME_LEN - 1u);
            return BOARD_CONFIG_OK;
        }
    }
    if (IS("link", "host")) {
        if (strncmp(v, "udp:", 4) == 0 && v[4] != '\0' && strlen(v + 4) < BOARD_CFG_STR) {
            c->link = BOARD_LINK_UDP;
            copy_str(c->link_target, sizeof(c->link_target), v + 4);
            return BOARD_CONFIG_OK;
        }
        if (strncmp(v, "ffs:", 4) == 0 && v[4] != '\0' && strlen(v + 4) < BOARD_CFG_STR) {
            c->link = BOARD_LINK_FFS;
            copy_str(c->link_target, sizeof(c->link_target), v + 4);
            return BOARD_CONFIG_OK;
        }
        return BAD("link.host '%s': expected udp:ADDR:PORT or ffs:DIR", v);
    }
    if (IS("link", "heartbeat_timeout_ms")) {
        if (!parse_long(v, 5, 10000, &x))
            return BAD("link.heartbeat_timeout_ms '%s': expected 5-10000", v);
        c->host_timeout_ms = (uint32_t)x;
        return BOARD_CONFIG_OK;
    }
    if (IS("link", "fade_ms")) {
        if (!parse_long(v, 0, 1000, &x))
            return BAD("link.fade_ms '%s': expected 0-1000", v);
        c->host_fade_ms = (uint32_t)x;
        return BOARD_CONFIG_OK;
    }
    if (IS("link", "key")) {
        if (v[0] == '\0' || strlen(v) >= BOARD_CFG_STR)
            return BAD("link.key '%s': expected a key file's path of 1-%u characters", v,
                       BOARD_CFG_STR - 1u);
        copy_str(c->link_key, sizeof(c->link_key), v);
        return BOARD_CONFIG_OK;
    }
    if (IS("link", "insecure")) {
        if (strcmp(v, "yes") == 0)
            c->link_insecure = true;
        else if (strcmp(v, "no") == 0)
            c->link_insecure = false;
        else
            return BAD("link.insecure '%s': expected yes or no", v);
        return BOARD_CONFIG_OK;
    }
    if (IS("loop", "rate_hz")) {
        if (!parse_long(v, 100, 10000, &x) || 1000000L % x != 0)
            return BAD("loop.rate_hz '%s': expected 100-10000 Hz dividing 1 s into whole "
                       "microseconds (1000, 2000, 4000)", v);
        c->rate_hz = (uint32_t)x;
        return BOARD_CONFIG_OK;
    }
    if (IS("loop", "rt_priority")) {
        if (!parse_long(v, 0, 99, &x))
            return BAD("loop.rt_priority '%s': expected 0-99", v);
        c->rt_priority = (int32_t)x;
        return BOARD_CONFIG_OK;
    }
    if (IS("link", "rt_priority")) {
        if (!parse_long(v, 0, 99, &x))
            return BAD("link.rt_priority '%s': expected 0-99", v);
        c->link_rt_priority = (int32_t)x;
        return BOARD_CONFIG_OK;
    }
    if (IS("loop", "cpu")) {
        if (!parse_long(v, -1, 1023, &x))
            return BAD("loop.cpu '%s': expected -1 (any) or a CPU number 0-1023", v);
        c->cpu = (int32_t)x;
        return BOARD_CONFIG_OK;
    }
    if (IS("loop", "overrun_streak")) {
        if (!parse_long(v, 0, 1000, &x))
            return BAD("loop.overrun_streak '%s': expected 0-1000", v);
        c->overrun_streak = (uint32_t)x;
        return BOARD_CONFIG_OK;
    }
    if (IS("loop", "stats_period_s")) {
        if (!parse_long(v, 0, 86400, &x))
            return BAD("loop.stats_period_s '%s': expected 0-86400", v);
        c->stats_period_s = (uint32_t)x;
        return BOARD_CONFIG_OK;
    }
    if (IS("loop", "duration_s")) {
        if (!parse_float(v, 0.0f, 1e6f, &f))
            return BAD("loop.duration_s '%s': expected 0-1000000 seconds", v);
        c->duration_s = f;
        return BOARD_CONFIG_OK;
    }
    if (IS("limits", "max_force_n")) {
        if (!parse_float(v, 0.01f, 20.0f, &f))
            return BAD("limits.max_force_n '%s': expected 0.01-20 N", v);
        c->max_force_n = f;
        return BOARD_CONFIG_OK;
    }
    if (IS("limits", "max_velocity_m_s")) {
        if (!parse_float(v, 0.0f, 20.0f, &f))
            return BAD("limits.max_velocity_m_s '%s': expected 0-20 m/s (0 = no limit)", v);
        c->max_velocity_m_s = f;
        return BOARD_CONFIG_OK;
    }
    if (IS("transform", "scale")) {
        if (!parse_float(v, 1e-3f, 1e3f, &f))
            return BAD("transform.scale '%s': expected 0.001-1000", v);
        c->model_scale = f;
        return BOARD_CONFIG_OK;
    }
    if (IS("transform", "offset_m")) {
        float o[3];
        char buf[96];
        if (strlen(v) >= sizeof(buf))
            return BAD("transform.offset_m: too long");
        copy_str(buf, sizeof(buf), v);
        char *p = buf;
        for (int i = 0; i < 3; i++) {
            char *comma = strchr(p, ',');
            if ((i < 2) != (comma != NULL))
                return BAD("transform.offset_m '%s': expected X,Y,Z in metres", v);
            if (comma)
                *comma = '\0';
            if (!parse_float(p, -100.0f, 100.0f, &o[i]))
                return BAD("transform.offset_m '%s': expected X,Y,Z in metres, each within "
                           "+-100", v);
            p = comma ? comma + 1 : p;
        }
        memcpy(c->model_offset_m, o, sizeof(o));
        return BOARD_CONFIG_OK;
    }
#undef IS
    snprintf(why, why_len, "unknown setting '%s.%s'", section, key);
    return BOARD_CONFIG_ERR_UNKNOWN;
}

/* board_config_parse_ini's state, shared by libinih's line reader and its setting handler:
 * the text, the line last handed to libinih and argil's first refusal. */
typedef struct {
    const char *text;
    size_t len;
    size_t at;                  /* the next byte to hand over */
    uint32_t line;              /* 1-based: the line libinih is reading */
    board_daemon_cfg_t *cfg;
    uint32_t refused_line;      /* 0 = nothing refused yet */
    board_config_err_t refused;
    char *why;
    size_t why_len;
} ini_text_t;

static bool is_blank(char ch)
{
    return ch == ' ' || ch == '\t';
}

/* Records argil's refusal of the current line; why is the caller's to write. */
static void ini_refuse(ini_text_t *t, board_config_err_t err)
{
    t->refused_line = t->line;
    t->refused = err;
}

/* True when a line that starts with '[' has more than blanks or a ';' comment after its first
 * ']' (libinih ignores the rest, so "[limits] max_force_n = 1" would lose its setting). */
static bool section_has_trailing_text(const char *s, size_t n)
{
    const char *close = memchr(s, ']', n);
    if (n == 0 || s[0] != '[' || close == NULL)
        return false;
    const char *p = close + 1;
    while (p < s + n && (is_blank(*p) || *p == '\r'))
        p++;
    return p < s + n && *p != ';';
}

/* libinih's reader (fgets-like): copies the next line of the text into buf (cap bytes) without
 * a UTF-8 byte-order mark or leading blanks, so libinih never takes an indented line for a
 * continuation of the value above. NULL at the end of the text or once argil refused a line. */
static char *ini_text_reader(char *buf, int cap, void *stream)
{
    ini_text_t *t = stream;
    if (t->refused_line != 0 || t->at >= t->len)
        return NULL;
    t->line++;
    const char *s = t->text + t->at;
    const char *nl = memchr(s, '\n', t->len - t->at);
    size_t n = nl != NULL ? (size_t)(nl - s) : t->len - t->at;
    t->at += nl != NULL ? n + 1u : n;
    /* libinih's documented limit: its buffer holds the line, "\r\n" and a NUL */
    const size_t max = cap > 3 ? (size_t)cap - 3u : 0u;
    const size_t shown = n > 0 && s[n - 1u] == '\r' ? n - 1u : n;
    if (memchr(s, '\0', n) != NULL) {
        ini_refuse(t, BOARD_CONFIG_ERR_NUL);
        snprintf(t->why, t->why_len, "NUL byte in the file");
        return NULL;
    }
    if (shown > max) {
        ini_refuse(t, BOARD_CONFIG_ERR_LINE_LONG);
        snprintf(t->why, t->why_len, "line longer than %zu characters", max);
        return NULL;
    }
    if (t->line == 1 && n >= 3 && memcmp(s, "\xEF\xBB\xBF", 3) == 0) {
        s += 3;
        n -= 3;
    }
    while (n > 0 && is_blank(*s)) {
        s++;
        n--;
    }
    if (section_has_trailing_text(s, n)) {
        ini_refuse(t, BOARD_CONFIG_ERR_AFTER_SECTION);
        snprintf(t->why, t->why_len, "text after the section's ']': a setting goes on a line "
                 "of its own");
        return NULL;
    }
    memcpy(buf, s, n);
    buf[n] = '\0';
    return buf;
}

/* libinih's handler: applies one key = value; returns nonzero to read on. */
static int ini_text_setting(void *user, const char *section, const char *key, const char *value)
{
    ini_text_t *t = user;
    if (section[0] == '\0') {
        ini_refuse(t, BOARD_CONFIG_ERR_NO_SECTION);
        snprintf(t->why, t->why_len, "'%s' is outside any [section]", key);
        return 0;
    }
    const board_config_err_t rc = board_config_set(t->cfg, section, key, value, t->why,
                                                   t->why_len);
    if (rc == BOARD_CONFIG_OK)
        return 1;
    ini_refuse(t, rc);
    const size_t n = strnlen(t->why, t->why_len);
    if (strchr(value, '#') != NULL && n < t->why_len)
        snprintf(t->why + n, t->why_len - n, "; inline comments start with ';'");
    return 0;
}

/* True when line (1-based) of the text starts with '[' after its blanks (and, on line 1, a
 * UTF-8 byte-order mark, which libinih skips). */
static bool line_starts_section(const char *text, size_t len, uint32_t line)
{
    size_t at = 0;
    for (uint32_t l = 1; l < line && at < len; at++)
        if (text[at] == '\n')
            l++;
    if (line == 1 && len >= 3 && memcmp(text, "\xEF\xBB\xBF", 3) == 0)
        at = 3;
    while (at < len && is_blank(text[at]))
        at++;
    return at < len && text[at] == '[';
}

board_config_err_t board_config_parse_ini(board_daemon_cfg_t *c, const char *text, size_t len,
                                          uint32_t *line, char *why, size_t why_len)
{
    board_daemon_cfg_t parsed = *c;
    ini_text_t t = {.text = text, .len = len, .cfg = &parsed, .why = why, .why_len = why_len};
    /* libinih returns the first line it refused (its own or the handler's) and reads on past
     * its own refusals; argil's reader stops at the first of argil's. */
    const int first = ini_parse_stream(ini_text_reader, &t, ini_text_setting, &t);
    if (first > 0 && (t.refused_line == 0 || (uint32_t)first < t.refused_line)) {
        /* libinih's two refusals: a '[' line without its ']', a line without '=' or ':' */
        *line = (uint32_t)first;
        const bool section = line_starts_section(text, len, *line);
        snprintf(why, why_len, "%s", section ? "expected [section]: no closing ']'"
                                             : "expected key = value or [section]");
        return section ? BOARD_CONFIG_ERR_SECTION : BOARD_CONFIG_ERR_NO_VALUE;
    }
    if (t.refused_line != 0) {
        *line = t.refused_line;
        return t.refused;
    }
    *line = t.line;
    if (first != 0) {
        snprintf(why, why_len, "libinih could not read the text (%d)", first);
        return BOARD_CONFIG_ERR_READER;
    }
    *c = parsed;
    return BOARD_CONFIG_OK;
}

board_config_err_t board_config_check(const board_daemon_cfg_t *c, char *why, size_t why_len)
{
    if (c->link_key[0] != '\0' && c->link_insecure) {
        snprintf(why, why_len, "link.key and link.insecure together: a keyed link is never "
                 "insecure; drop one");
        return BOARD_CONFIG_ERR_KEY_INSECURE;
    }
    if (c->link == BOARD_LINK_FFS && (c->link_key[0] != '\0' || c->link_insecure)) {
        snprintf(why, why_len, "link.%s is for the UDP link: USB (FunctionFS) is a cable to one "
                 "host and needs no key", c->link_key[0] != '\0' ? "key" : "insecure");
        return BOARD_CONFIG_ERR_USB_KEY;
    }
    if (c->host_fade_ms > c->host_timeout_ms * 10u) {
        snprintf(why, why_len, "link.fade_ms (%u) must not exceed ten host timeouts (%u ms)",
                 c->host_fade_ms, c->host_timeout_ms * 10u);
        return BOARD_CONFIG_ERR_FADE;
    }
    if (c->drive_heartbeat_ms * 1000u < 1000000u / c->rate_hz) {
        snprintf(why, why_len, "can.heartbeat_timeout_ms (%u) is shorter than one tick",
                 c->drive_heartbeat_ms);
        return BOARD_CONFIG_ERR_HEARTBEAT;
    }
    return BOARD_CONFIG_OK;
}
