/* SocketCAN error frames pass through can_batch_t unchanged from the Linux HAL to the CiA 402
 * master: id carries the error flag and class bits, data[1] the controller status. Values are
 * Linux's <linux/can/error.h> ones (checked against the kernel header in can_socket.c). */
#ifndef ARGIL_CAN_ERR_H
#define ARGIL_CAN_ERR_H

#define ARGIL_CAN_ERR_FLAG 0x20000000u      /* CAN_ERR_FLAG: this is an error frame */
#define ARGIL_CAN_ERR_CRTL 0x00000004u      /* CAN_ERR_CRTL: controller problem, see data[1] */
#define ARGIL_CAN_ERR_BUSOFF 0x00000040u    /* CAN_ERR_BUSOFF */
#define ARGIL_CAN_ERR_RESTARTED 0x00000100u /* CAN_ERR_RESTARTED: controller restarted */
#define ARGIL_CAN_CRTL_RX_PASSIVE 0x10u     /* CAN_ERR_CRTL_RX_PASSIVE */
#define ARGIL_CAN_CRTL_TX_PASSIVE 0x20u     /* CAN_ERR_CRTL_TX_PASSIVE */
#define ARGIL_CAN_CRTL_ACTIVE 0x40u         /* CAN_ERR_CRTL_ACTIVE: back to error-active */

#endif
