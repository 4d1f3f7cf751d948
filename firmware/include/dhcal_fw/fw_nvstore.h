/* fw_nvstore.h - the controller's non-volatile storage, as the port provides it.
 *
 * A byte-addressed region that keeps its contents across power cycles. Writes may be cut
 * short by a power failure at any byte: a cut write leaves the bytes before the cut
 * written and the rest as they were. The calibration store (fw_calstore.h) is built so
 * that such a cut never loses the previous calibration.
 */
#ifndef FW_NVSTORE_H
#define FW_NVSTORE_H

#include <stddef.h>
#include <stdint.h>

typedef enum {
    FW_NV_OK = 0,
    FW_NV_ERR_RANGE, /* offset + len beyond the region */
    FW_NV_ERR_IO     /* the device failed (or the power went) */
} fw_nv_status;

typedef struct {
    void *ctx;
    size_t size; /* bytes in the region */
    fw_nv_status (*read)(void *ctx, size_t offset, void *buf, size_t len);
    fw_nv_status (*write)(void *ctx, size_t offset, const void *buf, size_t len);
} fw_nvstore;

#endif /* FW_NVSTORE_H */
