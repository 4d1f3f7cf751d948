/* can_codec_dump.c - the C CAN codec (fw_can.h) as a line filter, for test_can_dbc.py to
 * hold against the DBC file through cantools. Host only (stdio).
 *
 * One request per input line, one answer line each:
 *   enc sync TICK                                     -> frame
 *   enc cmd J CODE ENABLE TICK                        -> frame
 *   enc fb J ENC TACHO ENABLED SATURATED FAULT TICK   -> frame
 *   enc wires W1 W2 W3 TICK                           -> frame
 *   dec ID LEN HEXDATA                                -> the decoded message as its enc line
 * frame = "frame ID LEN HEXDATA" (ID hex, data as 2*LEN hex digits); any codec error is
 * "err NAME" (fw_can_msg_status_name); a line that cannot be parsed is "bad" (numbers are
 * decimal except ID and HEXDATA; values are parsed as unsigned long and passed through
 * unclamped, so out-of-range inputs reach the encoder's checks).
 */
/* POSIX.1-2008: strtok_r. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal_can/fw_can.h"

#define MAX_FIELDS 10

static void print_frame(fw_can_msg_status st, const fw_can_frame *f)
{
    if (st != FW_CAN_MSG_OK) {
        printf("err %s\n", fw_can_msg_status_name(st));
        return;
    }
    printf("frame %03x %u ", (unsigned)f->id, (unsigned)f->len);
    for (unsigned i = 0U; i < f->len; ++i) {
        printf("%02x", (unsigned)f->data[i]);
    }
    printf("\n");
}

/* Splits line into whitespace-separated words (in place). */
static size_t split(char *line, char *word[MAX_FIELDS])
{
    size_t n = 0U;
    char *save = NULL;
    for (char *w = strtok_r(line, " \t\r\n", &save); w != NULL && n < MAX_FIELDS;
         w = strtok_r(NULL, " \t\r\n", &save)) {
        word[n++] = w;
    }
    return n;
}

static int to_ul(const char *s, int base, unsigned long *v)
{
    char *end = NULL;
    *v = strtoul(s, &end, base);
    return end != s && *end == '\0';
}

static int encode(char *word[MAX_FIELDS], size_t n)
{
    unsigned long v[8] = {0};
    for (size_t i = 2U; i < n; ++i) {
        if (!to_ul(word[i], 10, &v[i - 2U])) {
            return 0;
        }
    }
    fw_can_frame f;
    if (strcmp(word[1], "sync") == 0 && n == 3U) {
        const fw_can_sync m = {(uint16_t)v[0]};
        print_frame(fw_can_encode_sync(&m, &f), &f);
    } else if (strcmp(word[1], "cmd") == 0 && n == 6U) {
        const fw_can_drive_cmd m = {(uint16_t)v[1], (uint8_t)v[2], (uint16_t)v[3]};
        print_frame(fw_can_encode_drive_cmd((size_t)v[0], &m, &f), &f);
    } else if (strcmp(word[1], "fb") == 0 && n == 9U) {
        const fw_can_drive_fb m = {(uint16_t)v[1], (uint16_t)v[2], (uint8_t)v[3],
                                   (uint8_t)v[4],  (uint8_t)v[5],  (uint16_t)v[6]};
        print_frame(fw_can_encode_drive_fb((size_t)v[0], &m, &f), &f);
    } else if (strcmp(word[1], "wires") == 0 && n == 6U) {
        const fw_can_wires m = {{(uint16_t)v[0], (uint16_t)v[1], (uint16_t)v[2]}, (uint16_t)v[3]};
        print_frame(fw_can_encode_wires(&m, &f), &f);
    } else {
        return 0;
    }
    return 1;
}

static int decode(char *word[MAX_FIELDS], size_t n)
{
    unsigned long id = 0UL;
    unsigned long len = 0UL;
    if (n < 3U || n > 4U || !to_ul(word[1], 16, &id) || !to_ul(word[2], 10, &len) ||
        len > FW_CAN_MAX_DLC) {
        return 0;
    }
    fw_can_frame f;
    memset(&f, 0, sizeof f);
    f.id = (uint32_t)id;
    f.len = (uint8_t)len;
    const char *hex = n == 4U ? word[3] : "";
    if (strlen(hex) != 2U * len) {
        return 0;
    }
    for (size_t i = 0U; i < len; ++i) {
        const char byte[3] = {hex[2U * i], hex[2U * i + 1U], '\0'};
        unsigned long b = 0UL;
        if (!to_ul(byte, 16, &b)) {
            return 0;
        }
        f.data[i] = (uint8_t)b;
    }
    size_t j = 0U;
    fw_can_msg_status st = FW_CAN_MSG_ERR_ID;
    switch (fw_can_classify(f.id, NULL)) {
    case FW_CAN_KIND_SYNC: {
        fw_can_sync m;
        st = fw_can_decode_sync(&f, &m);
        if (st == FW_CAN_MSG_OK) {
            printf("enc sync %u\n", (unsigned)m.tick);
        }
        break;
    }
    case FW_CAN_KIND_DRIVE_CMD: {
        fw_can_drive_cmd m;
        st = fw_can_decode_drive_cmd(&f, &j, &m);
        if (st == FW_CAN_MSG_OK) {
            printf("enc cmd %zu %u %u %u\n", j, (unsigned)m.dac_code, (unsigned)m.enable,
                   (unsigned)m.tick);
        }
        break;
    }
    case FW_CAN_KIND_DRIVE_FB: {
        fw_can_drive_fb m;
        st = fw_can_decode_drive_fb(&f, &j, &m);
        if (st == FW_CAN_MSG_OK) {
            printf("enc fb %zu %u %u %u %u %u %u\n", j, (unsigned)m.encoder_counts,
                   (unsigned)m.tacho_code, (unsigned)m.enabled, (unsigned)m.saturated,
                   (unsigned)m.fault, (unsigned)m.tick);
        }
        break;
    }
    case FW_CAN_KIND_WIRES: {
        fw_can_wires m;
        st = fw_can_decode_wires(&f, &m);
        if (st == FW_CAN_MSG_OK) {
            printf("enc wires %u %u %u %u\n", (unsigned)m.counts[0], (unsigned)m.counts[1],
                   (unsigned)m.counts[2], (unsigned)m.tick);
        }
        break;
    }
    case FW_CAN_KIND_UNKNOWN: break;
    }
    if (st != FW_CAN_MSG_OK) {
        printf("err %s\n", fw_can_msg_status_name(st));
    }
    return 1;
}

int main(void)
{
    char line[512];
    while (fgets(line, sizeof line, stdin) != NULL) {
        char *word[MAX_FIELDS];
        const size_t n = split(line, word);
        int ok = 0;
        if (n >= 2U && strcmp(word[0], "enc") == 0) {
            ok = encode(word, n);
        } else if (n >= 3U && strcmp(word[0], "dec") == 0) {
            ok = decode(word, n);
        }
        if (!ok) {
            printf("bad\n");
        }
    }
    return 0;
}
