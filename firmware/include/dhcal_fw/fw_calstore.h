/* fw_calstore.h - calibration results in two slots with sequence number and CRC-32.
 *
 * The region holds slot A at offset 0 and slot B at offset FW_CAL_SLOT_SIZE. A save
 * writes the slot that does NOT hold the newest valid record, with sequence number one
 * above it, payload first and the header last; load picks the valid record with the
 * highest sequence number. An interrupted save therefore leaves the previous calibration
 * loadable whatever byte the power failed at (tests/firmware/test_calstore.c cuts it at
 * every offset). Records are little-endian, independent of the host's byte order.
 *
 * Record: magic "DHCA", format version, sequence (u32), payload length (u32), CRC-32
 * (IEEE 802.3, reflected, as zlib) over the 16 header bytes before it and the payload.
 * Format version 2 (docs/formats.md, section 7) holds every effect of the model, so that
 * whatever the controller's diagnosis adds is stored; version-1 records still load.
 */
#ifndef FW_CALSTORE_H
#define FW_CALSTORE_H

#include <stddef.h>
#include <stdint.h>

#include "dhcal/dhc_model.h"
#include "dhcal_fw/fw_nvstore.h"

#define FW_CAL_HEADER_SIZE 20U
#define FW_CAL_PAYLOAD_MAX 2048U
#define FW_CAL_SLOT_SIZE (FW_CAL_HEADER_SIZE + FW_CAL_PAYLOAD_MAX)

typedef enum {
    FW_CAL_OK = 0,
    FW_CAL_EMPTY,         /* no valid record in either slot (factory state) */
    FW_CAL_ERR_IO,        /* the storage failed; on save: the previous record is intact */
    FW_CAL_ERR_TOO_SMALL, /* the region cannot hold two slots */
    FW_CAL_ERR_MODEL      /* the model does not serialise (joint count) or is not finite */
} fw_cal_status;

/* CRC-32 (IEEE, reflected polynomial 0xEDB88320, initial and final xor 0xFFFFFFFF) of
 * len bytes, continuing from crc (start with 0). Bitwise: no table, small code. */
uint32_t fw_crc32(uint32_t crc, const void *data, size_t len);

/* Serialises / parses (the current format) the calibrated model (geometry, base, tool,
 * every joint effect, measurer, gravity, thermal, drift) as little-endian doubles. Returns
 * the payload length, 0 on error. */
size_t fw_cal_encode(const dhc_model *model, uint8_t *buf, size_t cap);
fw_cal_status fw_cal_decode(const uint8_t *buf, size_t len, dhc_model *model);

/* Saves the model as the newest record. *seq_out (may be NULL) receives its sequence.
 * On FW_CAL_ERR_IO the previously newest record is untouched. */
fw_cal_status fw_cal_save(const fw_nvstore *nv, const dhc_model *model, uint32_t *seq_out);

/* Loads the newest valid record. FW_CAL_EMPTY when neither slot is valid. */
fw_cal_status fw_cal_load(const fw_nvstore *nv, dhc_model *model, uint32_t *seq_out);

#endif /* FW_CALSTORE_H */
