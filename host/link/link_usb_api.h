/* The libusb-1.0 entry points the USB link uses. link_usb_open resolves them from
 * libusb-1.0.so.0 with dlopen; tests hand link_usb_open_api a table of fakes that model
 * libusb's object lifetimes, so the link's open / unplug / rescan / reopen paths run without a
 * device. */
#ifndef ARGIL_LINK_USB_API_H
#define ARGIL_LINK_USB_API_H

#include <libusb-1.0/libusb.h>
#include <stddef.h>

#include "host/link/link.h"

typedef struct {
    void *lib;                       /* the dlopen handle, closed with the link; NULL for fakes */
    __typeof__(libusb_init) *init;
    __typeof__(libusb_exit) *exit;
    __typeof__(libusb_get_device_list) *get_device_list;
    __typeof__(libusb_free_device_list) *free_device_list;
    __typeof__(libusb_get_device_descriptor) *get_device_descriptor;
    __typeof__(libusb_get_bus_number) *get_bus_number;
    __typeof__(libusb_get_port_numbers) *get_port_numbers;
    __typeof__(libusb_open) *open;
    __typeof__(libusb_close) *close;
    __typeof__(libusb_control_transfer) *control_transfer;
    __typeof__(libusb_set_auto_detach_kernel_driver) *set_auto_detach_kernel_driver;
    __typeof__(libusb_claim_interface) *claim_interface;
    __typeof__(libusb_release_interface) *release_interface;
    __typeof__(libusb_set_interface_alt_setting) *set_interface_alt_setting;
    __typeof__(libusb_alloc_transfer) *alloc_transfer;
    __typeof__(libusb_free_transfer) *free_transfer;
    __typeof__(libusb_submit_transfer) *submit_transfer;
    __typeof__(libusb_cancel_transfer) *cancel_transfer;
    __typeof__(libusb_handle_events_timeout_completed) *handle_events_timeout_completed;
    __typeof__(libusb_has_capability) *has_capability;
    __typeof__(libusb_hotplug_register_callback) *hotplug_register_callback;
    __typeof__(libusb_hotplug_deregister_callback) *hotplug_deregister_callback;
    __typeof__(libusb_error_name) *error_name;
} usb_api_t;

/* link_usb_open with the entry points given (the table is copied; api->lib, when set, is
 * dlclosed with the link, also when the open fails). */
argil_err_t link_usb_open_api(link_t *l, const usb_api_t *api, char *err, size_t err_len);

#endif
