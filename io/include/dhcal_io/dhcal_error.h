/* dhcal_error.h - how the file layer reports: a status code and one message.
 *
 * Every loader validates every field; on bad input it returns DHCAL_IO_BAD_INPUT and writes
 * one message naming the file and the line (CSV) or the JSON path (model) into err->msg.
 * Missing files, unreadable files and every defect of the content are DHCAL_IO_BAD_INPUT;
 * DHCAL_IO_FAILED is kept for out of memory and for failures to write.
 */
#ifndef DHCAL_ERROR_H
#define DHCAL_ERROR_H

enum { DHCAL_IO_OK = 0, DHCAL_IO_FAILED = 1, DHCAL_IO_BAD_INPUT = 2 };

typedef struct {
    char msg[1024];
} dhcal_error;

#if defined(__GNUC__)
#define DHCAL_PRINTF(fmt_index, first_arg) __attribute__((format(printf, fmt_index, first_arg)))
#else
#define DHCAL_PRINTF(fmt_index, first_arg)
#endif

/* Writes the message into err (when err is not NULL) and returns code. */
int dhcal_error_set(dhcal_error *err, int code, const char *fmt, ...) DHCAL_PRINTF(3, 4);

#endif /* DHCAL_ERROR_H */
