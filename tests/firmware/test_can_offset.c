/* test_can_offset.c - the protocol moved by an identifier offset (fw_can_offset): frames
 * leave with the DBC's identifiers plus the offset and come back without it, identifiers
 * outside the moved range become foreign, and what cannot fit 11 bits is refused. The
 * expected bus identifiers are written out by hand from the DBC (0x080, 0x100 + j,
 * 0x180 + j, 0x200), not computed by the code under test. */
#include <string.h>

#include "dhcal_can/fw_can.h"
#include "dhcal_can/fw_can_offset.h"
#include "unity.h"

/* A bus that records what is sent and hands out a queue of frames. */
#define BUS_CAP 8U
typedef struct {
    fw_can_frame sent[BUS_CAP];
    size_t n_sent;
    fw_can_frame queue[BUS_CAP];
    fw_can_status queue_status[BUS_CAP];
    size_t n_queue;
    size_t next;
} fake_bus;

static fw_can_status fake_send(void *ctx, const fw_can_frame *frame)
{
    fake_bus *b = (fake_bus *)ctx;
    TEST_ASSERT_TRUE(b->n_sent < BUS_CAP);
    b->sent[b->n_sent++] = *frame;
    return FW_CAN_OK;
}

static fw_can_status fake_recv(void *ctx, fw_can_frame *frame, uint32_t timeout_us)
{
    (void)timeout_us;
    fake_bus *b = (fake_bus *)ctx;
    if (b->next == b->n_queue) {
        return FW_CAN_TIMEOUT;
    }
    *frame = b->queue[b->next];
    return b->queue_status[b->next++];
}

static fake_bus bus;
static fw_can_transport inner;
static fw_can_offset wrap;
static fw_can_transport moved;

static void push(uint32_t id, fw_can_status st)
{
    fw_can_frame f;
    memset(&f, 0, sizeof f);
    f.id = id;
    f.len = 6U;
    f.data[0] = (uint8_t)(id & 0xFFU);
    bus.queue[bus.n_queue] = f;
    bus.queue_status[bus.n_queue++] = st;
}

void setUp(void)
{
    memset(&bus, 0, sizeof bus);
    inner.ctx = &bus;
    inner.send = fake_send;
    inner.recv = fake_recv;
    TEST_ASSERT_EQUAL_INT(0, fw_can_offset_init(&wrap, &inner, 0x300U, &moved));
}

void tearDown(void) {}

static void test_sent_frames_carry_the_offset_and_the_same_data(void)
{
    fw_can_frame f;
    const fw_can_sync sync = {0x1234U};
    TEST_ASSERT_EQUAL(FW_CAN_MSG_OK, fw_can_encode_sync(&sync, &f));
    TEST_ASSERT_EQUAL(FW_CAN_OK, moved.send(moved.ctx, &f));
    const fw_can_drive_cmd cmd = {3000U, 1U, 7U};
    TEST_ASSERT_EQUAL(FW_CAN_MSG_OK, fw_can_encode_drive_cmd(2U, &cmd, &f));
    TEST_ASSERT_EQUAL(FW_CAN_OK, moved.send(moved.ctx, &f));
    TEST_ASSERT_EQUAL_size_t(2U, bus.n_sent);
    TEST_ASSERT_EQUAL_HEX32(0x380U, bus.sent[0].id);
    TEST_ASSERT_EQUAL_HEX32(0x402U, bus.sent[1].id);
    TEST_ASSERT_EQUAL_UINT8(FW_CAN_DLC_SYNC, bus.sent[0].len);
    TEST_ASSERT_EQUAL_HEX8(0x34U, bus.sent[0].data[0]); /* little-endian tick */
    TEST_ASSERT_EQUAL_HEX8(0x12U, bus.sent[0].data[1]);
    TEST_ASSERT_EQUAL_HEX32(0x380U, fw_can_offset_bus_id(0x300U, FW_CAN_ID_SYNC));
}

static void test_received_frames_lose_the_offset_and_strangers_become_foreign(void)
{
    push(0x481U, FW_CAN_OK); /* DRIVE_FB_1 moved */
    push(0x500U, FW_CAN_OK); /* MEAS_WIRES moved */
    push(0x181U, FW_CAN_OK); /* DRIVE_FB_1 of an arm without the offset: not ours */
    push(0x000U, FW_CAN_OK);
    push(0x7FFU, FW_CAN_OK); /* moved back to 0x4FF: inside 11 bits, no message of ours */
    push(0x482U, FW_CAN_OVERRUN);
    fw_can_frame f;
    size_t drive = 99U;
    TEST_ASSERT_EQUAL(FW_CAN_OK, moved.recv(moved.ctx, &f, 100U));
    TEST_ASSERT_EQUAL_HEX32(0x181U, f.id);
    TEST_ASSERT_EQUAL(FW_CAN_KIND_DRIVE_FB, fw_can_classify(f.id, &drive));
    TEST_ASSERT_EQUAL_size_t(1U, drive);
    TEST_ASSERT_EQUAL_HEX8(0x81U, f.data[0]); /* the data are not touched */
    TEST_ASSERT_EQUAL(FW_CAN_OK, moved.recv(moved.ctx, &f, 100U));
    TEST_ASSERT_EQUAL_HEX32(0x200U, f.id);
    TEST_ASSERT_EQUAL(FW_CAN_OK, moved.recv(moved.ctx, &f, 100U));
    TEST_ASSERT_EQUAL_HEX32(FW_CAN_ID_FOREIGN, f.id);
    TEST_ASSERT_EQUAL(FW_CAN_KIND_UNKNOWN, fw_can_classify(f.id, &drive));
    TEST_ASSERT_EQUAL(FW_CAN_OK, moved.recv(moved.ctx, &f, 100U));
    TEST_ASSERT_EQUAL_HEX32(FW_CAN_ID_FOREIGN, f.id);
    TEST_ASSERT_EQUAL(FW_CAN_OK, moved.recv(moved.ctx, &f, 100U));
    TEST_ASSERT_EQUAL_HEX32(0x4FFU, f.id);
    TEST_ASSERT_EQUAL(FW_CAN_KIND_UNKNOWN, fw_can_classify(f.id, &drive));
    /* an overrun still hands its frame over, moved back like any other */
    TEST_ASSERT_EQUAL(FW_CAN_OVERRUN, moved.recv(moved.ctx, &f, 100U));
    TEST_ASSERT_EQUAL_HEX32(0x182U, f.id);
    TEST_ASSERT_EQUAL(FW_CAN_TIMEOUT, moved.recv(moved.ctx, &f, 100U));
}

static void test_zero_offset_is_the_dbc(void)
{
    TEST_ASSERT_EQUAL_INT(0, fw_can_offset_init(&wrap, &inner, 0U, &moved));
    push(0x181U, FW_CAN_OK);
    fw_can_frame f;
    TEST_ASSERT_EQUAL(FW_CAN_OK, moved.recv(moved.ctx, &f, 100U));
    TEST_ASSERT_EQUAL_HEX32(0x181U, f.id);
}

static void test_offsets_that_leave_11_bits_are_refused(void)
{
    /* 0x5FF + 0x200 = 0x7FF is the last that fits */
    TEST_ASSERT_EQUAL_INT(0, fw_can_offset_init(&wrap, &inner, 0x5FFU, &moved));
    fw_can_transport untouched = moved;
    TEST_ASSERT_EQUAL_INT(-1, fw_can_offset_init(&wrap, &inner, 0x600U, &moved));
    TEST_ASSERT_EQUAL_PTR(untouched.ctx, moved.ctx);
    TEST_ASSERT_EQUAL_INT(-1, fw_can_offset_init(NULL, &inner, 0U, &moved));
    TEST_ASSERT_EQUAL_INT(-1, fw_can_offset_init(&wrap, NULL, 0U, &moved));
    fw_can_transport half = inner;
    half.recv = NULL;
    TEST_ASSERT_EQUAL_INT(-1, fw_can_offset_init(&wrap, &half, 0U, &moved));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_sent_frames_carry_the_offset_and_the_same_data);
    RUN_TEST(test_received_frames_lose_the_offset_and_strangers_become_foreign);
    RUN_TEST(test_zero_offset_is_the_dbc);
    RUN_TEST(test_offsets_that_leave_11_bits_are_refused);
    return UNITY_END();
}
