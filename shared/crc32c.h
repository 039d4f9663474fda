/* CRC-32C (Castagnoli, reflected polynomial 0x82F63B78), as used by the wire protocol. */
#ifndef ARGIL_CRC32C_H
#define ARGIL_CRC32C_H

#include <stddef.h>
#include <stdint.h>

/* Continues a CRC-32C over data; start with crc = 0. crc32c(0, "123456789", 9) = 0xE3069283. */
uint32_t crc32c(uint32_t crc, const void *data, size_t len);

#endif
