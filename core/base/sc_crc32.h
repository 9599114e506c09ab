/*
 * sc_crc32.h: CRC-32 (IEEE 802.3 / zlib / PNG): reflected polynomial 0xEDB88320, initial value
 * 0xFFFFFFFF, final XOR 0xFFFFFFFF. Check value: CRC of the ASCII bytes "123456789" is
 * 0xCBF43926. Used by the case file sections and the display link packets.
 *
 * Thread and memory rules: pure functions over caller bytes, reentrant; the 8 KiB of tables
 * (slicing-by-8) are const (flash on an MCU). Never allocates, never calls the OS, cannot fail.
 */
#ifndef SC_CRC32_H
#define SC_CRC32_H

#include <stddef.h>
#include <stdint.h>

/* Initial running value for sc_crc32_update(). */
#define SC_CRC32_INIT 0xFFFFFFFFu

/* CRC-32 of n bytes in one call. O(n), eight table lookups per 8 bytes. data may be NULL when
 * n == 0. */
uint32_t sc_crc32(const void *data, size_t n);

/* Incremental form: crc = SC_CRC32_INIT; crc = sc_crc32_update(crc, a, na); ...;
 * result = sc_crc32_final(crc). Equals sc_crc32() of the concatenation. O(n). */
uint32_t sc_crc32_update(uint32_t crc, const void *data, size_t n);
uint32_t sc_crc32_final(uint32_t crc);

#endif /* SC_CRC32_H */
