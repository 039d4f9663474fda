/* CRC-32C (Castagnoli) that seals every wire-protocol frame; a nibble table keeps it small
 * enough for an MCU and fast enough for 1 KiB frames at 1 kHz. */
#include "crc32c.h"

/* Reflected polynomial 0x82F63B78 applied to each 4-bit value: t[n] = crc of n over 4 shifts. */
static const uint32_t crc32c_nibble[16] = {
    0x00000000u, 0x105EC76Fu, 0x20BD8EDEu, 0x30E349B1u, 0x417B1DBCu, 0x5125DAD3u,
    0x61C69362u, 0x7198540Du, 0x82F63B78u, 0x92A8FC17u, 0xA24BB5A6u, 0xB21572C9u,
    0xC38D26C4u, 0xD3D3E1ABu, 0xE330A81Au, 0xF36E6F75u,
};

/* Returns the CRC-32C of data continued from crc (0 to start); init ~0 and final xor are inside. */
uint32_t crc32c(uint32_t crc, const void *data, size_t len)
{
    const uint8_t *p = (const uint8_t *)data;
    uint32_t c = ~crc;
    for (size_t i = 0; i < len; i++) {
        c ^= p[i];
        c = (c >> 4) ^ crc32c_nibble[c & 0x0Fu];
        c = (c >> 4) ^ crc32c_nibble[c & 0x0Fu];
    }
    return ~c;
}
