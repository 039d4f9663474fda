/* The device string of the host link: which board to talk to and over what ("sim",
 * "sim:press", "udp:HOST:PORT", "usb", "usb:VID:PID", "usb:BUS-PORT.PORT…"). Parsing only;
 * nothing opens. */
#ifndef ARGIL_LINK_SPEC_H
#define ARGIL_LINK_SPEC_H

#include <stdbool.h>
#include <stdint.h>

#define LINK_SPEC_HOST_MAX 64u        /* bytes of a UDP host name, with the NUL */
#define LINK_SPEC_PORTS_MAX 7u        /* USB hub depth (libusb_get_port_numbers) */
#define LINK_SPEC_DEFAULT_VID 0x1209u /* pid.codes test VID, as firmware/board/argil-gadget.sh */
#define LINK_SPEC_DEFAULT_PID 0x0001u

typedef enum { LINK_KIND_SIM = 1, LINK_KIND_UDP, LINK_KIND_USB } link_kind_t;

typedef enum {
    LINK_SPEC_OK = 0,
    LINK_SPEC_ERR_EMPTY = -1,      /* no string, or an empty one */
    LINK_SPEC_ERR_KIND = -2,       /* not sim, udp: or usb */
    LINK_SPEC_ERR_SIM_ARGS = -3,   /* "sim" takes nothing after it but ":press" */
    LINK_SPEC_ERR_UDP_FORM = -4,   /* udp without HOST:PORT */
    LINK_SPEC_ERR_UDP_HOST = -5,   /* empty, too long, or bad characters */
    LINK_SPEC_ERR_UDP_PORT = -6,   /* not a whole number 1..65535 */
    LINK_SPEC_ERR_USB_ID = -7,     /* VID or PID not 1..4 hex digits */
    LINK_SPEC_ERR_USB_BUS = -8,    /* bus not a number 1..255 */
    LINK_SPEC_ERR_USB_PORT = -9,   /* a port not a number 1..255 */
    LINK_SPEC_ERR_USB_DEPTH = -10, /* more than LINK_SPEC_PORTS_MAX ports */
    LINK_SPEC_ERR_USB_FORM = -11   /* neither VID:PID nor BUS-PORT[.PORT…] */
} link_spec_err_t;

/* What the simulated board's hand does with the stylus. */
typedef enum {
    LINK_SIM_HAND_STILL = 0,       /* "sim": holds it still 10 mm above the clay, no button */
    LINK_SIM_HAND_PRESS            /* "sim:press": presses it into the clay with button 1 held,
                                    * once every LINK_SIM_PRESS_PERIOD_S (link_sim.c) */
} link_sim_hand_t;

typedef struct {
    link_kind_t kind;
    link_sim_hand_t sim_hand;        /* sim */
    char host[LINK_SPEC_HOST_MAX];   /* udp */
    uint16_t port;                   /* udp */
    uint16_t vid, pid;               /* usb: the device to find (default 1209:0001) */
    bool by_path;                    /* usb: find by bus and port path instead */
    uint8_t bus;
    uint8_t ports[LINK_SPEC_PORTS_MAX];
    uint8_t n_ports;
} link_spec_t;

/* Parses s into spec; on an error spec is unspecified and the code names the rule broken. */
link_spec_err_t link_spec_parse(const char *s, link_spec_t *spec);

/* What the rule of err asks for, in one phrase (for "bad device 'X': <phrase>"). */
const char *link_spec_err_text(link_spec_err_t err);

#endif
