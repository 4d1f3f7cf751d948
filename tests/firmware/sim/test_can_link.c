/* test_can_link.c - the controller over CAN: fw_ctrl over fw_can_link over an in-memory
 * queue transport over dhs_bus (the drives and the measurer) over the plant, against the
 * same controller over the sim port (fw_sim_port) on a twin plant with the same scenario
 * and run seed.
 *   - tick for tick the same encoder, tacho and wire readings and the same DAC commands,
 *     the same times, the same final joint angles, wire lengths and true arm state,
 *     bit for bit: the protocol adds nothing and loses nothing;
 *   - a lost feedback frame (any of the four) -> FW_FAULT_PORT_TIMEOUT, the lost frame
 *     counted, the drives commanded to mid-scale (0 V) and at mid-scale in the plant;
 *   - a late frame (an answer to an older SYNC, carrying a wild encoder value) is counted
 *     and not used: the controller runs on unharmed; a frame held back one tick makes
 *     that tick time out, then arrives late and is discarded;
 *   - the nodes stop answering -> FW_FAULT_PORT_TIMEOUT with mid-scale commands sent;
 *   - transport overrun and a drive's Fault bit -> FW_FAULT_PORT_IO; malformed and foreign
 *     frames are counted and ignored; a drive without commands goes to 0 V by itself.
 * Host only (links host_sim). */
#include <string.h>

#include "dhcal_fw/fw_can_link.h"
#include "dhcal_fw/fw_controller.h"
#include "dhcal_sim/dhs_bus.h"
#include "fw_sim_port.h"
#include "sim_fixture.h"
#include "unity.h"

/* ---------------------------------------------------------------- the in-memory bus */

#define QUEUE_CAP 32U

/* The controller's transport: send hands the frame to the nodes at once (they answer
 * into the receive queue), recv pops the queue. Frames can be put in front of the nodes'
 * answers to a SYNC (inject), and the queue can be made to overflow. */
typedef struct {
    dhs_bus *bus;
    fw_can_frame rx[QUEUE_CAP];
    size_t head;
    size_t count;
    size_t cap; /* QUEUE_CAP unless a test shrinks it */
    int overflowed;
    fw_can_frame inject[4];
    size_t n_inject;
    uint64_t inject_at_sync; /* put inject[] into the queue when this SYNC is sent (0: off) */
    uint64_t syncs_sent;
    uint16_t last_cmd[FW_CAN_MAX_DRIVES]; /* DAC codes of the last commands sent */
    uint32_t cmds_sent;
} mem_bus;

static void push(void *ctx, const fw_can_frame *f)
{
    mem_bus *m = ctx;
    if (m->count == m->cap) {
        m->overflowed = 1;
        return;
    }
    m->rx[(m->head + m->count) % QUEUE_CAP] = *f;
    ++m->count;
}

static fw_can_status mem_send(void *ctx, const fw_can_frame *f)
{
    mem_bus *m = ctx;
    size_t j = 0U;
    const fw_can_kind kind = fw_can_classify(f->id, &j);
    if (kind == FW_CAN_KIND_SYNC) {
        ++m->syncs_sent;
        if (m->inject_at_sync != 0U && m->syncs_sent == m->inject_at_sync) {
            for (size_t i = 0U; i < m->n_inject; ++i) {
                push(m, &m->inject[i]);
            }
        }
    } else if (kind == FW_CAN_KIND_DRIVE_CMD) {
        fw_can_drive_cmd cmd;
        TEST_ASSERT_EQUAL(FW_CAN_MSG_OK, fw_can_decode_drive_cmd(f, &j, &cmd));
        m->last_cmd[j] = cmd.dac_code;
        ++m->cmds_sent;
    }
    (void)dhs_bus_handle(m->bus, f, push, m);
    return FW_CAN_OK;
}

static fw_can_status mem_recv(void *ctx, fw_can_frame *f, uint32_t timeout_us)
{
    mem_bus *m = ctx;
    TEST_ASSERT_TRUE(timeout_us > 0U);
    if (m->overflowed) {
        m->overflowed = 0;
        m->count = 0U; /* what a full kernel queue looks like afterwards: frames gone */
        return FW_CAN_OVERRUN;
    }
    if (m->count == 0U) {
        return FW_CAN_TIMEOUT; /* nothing else can arrive: the nodes answer inside send */
    }
    *f = m->rx[m->head];
    m->head = (m->head + 1U) % QUEUE_CAP;
    --m->count;
    return FW_CAN_OK;
}

/* ---------------------------------------------------------------- a recording port */

#define MAX_TICKS 20000U

/* What a controller saw and did at each tick (index 0: before the first tick). */
typedef struct {
    uint16_t enc[DHC_MAX_JOINTS];
    uint16_t tacho[DHC_MAX_JOINTS];
    uint16_t wires[3];
    uint16_t dac[DHC_MAX_JOINTS];
    uint64_t t_us;
} tick_log;

typedef struct {
    const fw_port *inner;
    size_t tick;
    tick_log log[MAX_TICKS];
} recorder;

static tick_log *rec_entry(recorder *r)
{
    TEST_ASSERT_TRUE(r->tick < MAX_TICKS);
    return &r->log[r->tick];
}

static fw_port_status rec_wait_tick(void *ctx, uint64_t *t_us)
{
    recorder *r = ctx;
    ++r->tick;
    const fw_port_status st = r->inner->wait_tick(r->inner->ctx, t_us);
    rec_entry(r)->t_us = st == FW_PORT_OK ? *t_us : 0U;
    return st;
}

static fw_port_status rec_read_encoders(void *ctx, uint16_t counts[DHC_MAX_JOINTS])
{
    recorder *r = ctx;
    const fw_port_status st = r->inner->read_encoders(r->inner->ctx, counts);
    memcpy(rec_entry(r)->enc, counts, sizeof rec_entry(r)->enc);
    return st;
}

static fw_port_status rec_read_tachos(void *ctx, uint16_t codes[DHC_MAX_JOINTS])
{
    recorder *r = ctx;
    const fw_port_status st = r->inner->read_tachos(r->inner->ctx, codes);
    memcpy(rec_entry(r)->tacho, codes, sizeof rec_entry(r)->tacho);
    return st;
}

static fw_port_status rec_read_wires(void *ctx, uint16_t counts[3])
{
    recorder *r = ctx;
    const fw_port_status st = r->inner->read_wires(r->inner->ctx, counts);
    memcpy(rec_entry(r)->wires, counts, sizeof rec_entry(r)->wires);
    return st;
}

static fw_port_status rec_write_dacs(void *ctx, const uint16_t codes[DHC_MAX_JOINTS])
{
    recorder *r = ctx;
    memcpy(rec_entry(r)->dac, codes, sizeof rec_entry(r)->dac);
    return r->inner->write_dacs(r->inner->ctx, codes);
}

static void recorder_wrap(recorder *r, const fw_port *inner, fw_port *outer)
{
    memset(r, 0, sizeof *r);
    r->inner = inner;
    *outer = *inner;
    outer->ctx = r;
    outer->wait_tick = rec_wait_tick;
    outer->read_encoders = rec_read_encoders;
    outer->read_tachos = rec_read_tachos;
    outer->read_wires = rec_read_wires;
    outer->write_dacs = rec_write_dacs;
}

/* ---------------------------------------------------------------- the two set-ups */

static const double q_start[3] = {0.0, 60.0 * SIM_DEG, -60.0 * SIM_DEG};
#define RUN_SEED 7U

static dhs_scenario sc;
static fw_io_config io;
static fw_ctrl_config cfg;
static double wire_start_mm[3];

static fw_sim sim; /* reference: the sim port */
static fw_port sim_port;
static recorder sim_rec;
static fw_port sim_rec_port;
static fw_ctrl sim_ctrl;

static dhs_plant can_plant; /* the same world behind the bus */
static dhs_bus bus;
static mem_bus mem;
static fw_can_link link;
static fw_port can_port;
static recorder can_rec;
static fw_port can_rec_port;
static fw_ctrl can_ctrl;

static void setup_world(int variant)
{
    sim_fixture_paper_arm(&sc, variant);
    fw_sim_io_config(&sc, &io);
    fw_ctrl_default_config(&cfg, 3U);
    dhc_arm nominal;
    sim_fixture_nominal(&nominal);
    fw_ctrl_config_limits(&cfg, &nominal);

    TEST_ASSERT_EQUAL(DHC_OK, fw_sim_init(&sim, &sc, RUN_SEED, q_start, &sim_port));
    dhs_plant_truth t;
    dhs_plant_get_truth(&sim.plant, &t);
    memcpy(wire_start_mm, t.wire_mm, sizeof wire_start_mm);

    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_init(&can_plant, &sc, RUN_SEED, q_start));
    TEST_ASSERT_EQUAL(DHC_OK, dhs_bus_init(&bus, &can_plant));
    memset(&mem, 0, sizeof mem);
    mem.bus = &bus;
    mem.cap = QUEUE_CAP;
    const fw_can_transport tr = {&mem, mem_send, mem_recv};
    fw_can_link_config lc;
    fw_can_link_default_config(&lc, 3U);
    memset(&can_port, 0, sizeof can_port);
    TEST_ASSERT_EQUAL(FW_PORT_OK, fw_can_link_init(&link, &tr, &lc, &can_port));
    TEST_ASSERT_NULL(can_port.nv.read); /* left to the caller */
    TEST_ASSERT_EQUAL(FW_PORT_OK, fw_can_link_start(&link));
}

static void init_can_ctrl(void)
{
    recorder_wrap(&can_rec, &can_port, &can_rec_port);
    TEST_ASSERT_EQUAL(FW_FAULT_NONE,
                      fw_ctrl_init(&can_ctrl, &can_rec_port, &io, &cfg, q_start, wire_start_mm));
}

void setUp(void)
{
    setup_world(SIM_FIXTURE_RIGID);
    init_can_ctrl();
}

void tearDown(void) {}

static void assert_plant_drives_zero(void)
{
    for (size_t j = 0U; j < 3U; ++j) {
        TEST_ASSERT_EQUAL_UINT16(DHS_DAC_ZERO, can_plant.dac[j]);
    }
}

static void assert_commands_sent_zero(void)
{
    for (size_t j = 0U; j < 3U; ++j) {
        TEST_ASSERT_EQUAL_UINT16(FW_CAN_CODE_ZERO, mem.last_cmd[j]);
    }
}

static void run_ticks(size_t n)
{
    for (size_t k = 0U; k < n; ++k) {
        TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_ctrl_tick(&can_ctrl, q_start, NULL));
    }
}

/* ---------------------------------------------------------------- equivalence */

static void run_equivalence(int variant)
{
    setup_world(variant);
    init_can_ctrl();
    recorder_wrap(&sim_rec, &sim_port, &sim_rec_port);
    TEST_ASSERT_EQUAL(FW_FAULT_NONE,
                      fw_ctrl_init(&sim_ctrl, &sim_rec_port, &io, &cfg, q_start, wire_start_mm));

    const double q1[3] = {0.3, 1.2, -0.8};
    const int8_t dir1[3] = {1, -1, 1};
    const double q2[3] = {-0.2, 0.9, -0.4};
    const int8_t dir2[3] = {-1, 1, -1};
    double w_sim[3];
    double w_can[3];
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_ctrl_move_to(&sim_ctrl, q1, dir1));
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_ctrl_move_to(&sim_ctrl, q2, dir2));
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_ctrl_hold(&sim_ctrl, 50U, w_sim));
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_ctrl_move_to(&can_ctrl, q1, dir1));
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_ctrl_move_to(&can_ctrl, q2, dir2));
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_ctrl_hold(&can_ctrl, 50U, w_can));

    /* the moves really happened: far from the start, on the target */
    TEST_ASSERT_TRUE(sim_rec.tick > 1000U);
    for (size_t j = 0U; j < 3U; ++j) {
        TEST_ASSERT_DOUBLE_WITHIN(2e-4, q2[j], can_ctrl.q_rad[j]);
    }
    /* tick for tick, every reading and command */
    TEST_ASSERT_EQUAL_size_t(sim_rec.tick, can_rec.tick);
    for (size_t k = 0U; k <= sim_rec.tick; ++k) {
        const tick_log *a = &sim_rec.log[k];
        const tick_log *b = &can_rec.log[k];
        TEST_ASSERT_EQUAL_HEX16_ARRAY_MESSAGE(a->enc, b->enc, DHC_MAX_JOINTS, "encoders");
        TEST_ASSERT_EQUAL_HEX16_ARRAY_MESSAGE(a->tacho, b->tacho, DHC_MAX_JOINTS, "tachos");
        TEST_ASSERT_EQUAL_HEX16_ARRAY_MESSAGE(a->wires, b->wires, 3, "wires");
        TEST_ASSERT_EQUAL_HEX16_ARRAY_MESSAGE(a->dac, b->dac, DHC_MAX_JOINTS, "DACs");
        TEST_ASSERT_EQUAL_UINT64(a->t_us, b->t_us);
    }
    /* the end state, bit for bit */
    TEST_ASSERT_EQUAL_MEMORY(sim_ctrl.q_rad, can_ctrl.q_rad, sizeof sim_ctrl.q_rad);
    TEST_ASSERT_EQUAL_MEMORY(sim_ctrl.dir, can_ctrl.dir, sizeof sim_ctrl.dir);
    TEST_ASSERT_EQUAL_MEMORY(w_sim, w_can, sizeof w_sim);
    dhs_plant_truth ts;
    dhs_plant_truth tc;
    dhs_plant_get_truth(&sim.plant, &ts);
    dhs_plant_get_truth(&can_plant, &tc);
    TEST_ASSERT_EQUAL_MEMORY(&ts, &tc, sizeof ts);
    /* and the protocol itself was clean */
    TEST_ASSERT_EQUAL_UINT64(sim_rec.tick + 1U, link.counters.ticks);
    TEST_ASSERT_EQUAL_UINT64(link.counters.ticks, link.counters.complete);
    TEST_ASSERT_EQUAL_UINT32(0U, link.counters.lost + link.counters.late + link.counters.future +
                                     link.counters.duplicate + link.counters.malformed +
                                     link.counters.foreign + link.counters.overruns);
    TEST_ASSERT_EQUAL_UINT32(0U, bus.stale_commands + bus.malformed + bus.watchdog_trips);
    TEST_ASSERT_EQUAL_UINT32((uint32_t)(3U * sim_rec.tick), mem.cmds_sent);
}

static void test_same_readings_and_positions_as_the_sim_port_rigid_arm(void)
{
    run_equivalence(SIM_FIXTURE_RIGID);
}

static void test_same_readings_and_positions_as_the_sim_port_every_effect(void)
{
    run_equivalence(SIM_FIXTURE_ALL_EFFECTS);
}

/* ---------------------------------------------------------------- faults */

static void test_a_lost_feedback_frame_stops_the_drives(void)
{
    const uint32_t ids[4] = {FW_CAN_ID_DRIVE_FB_BASE, FW_CAN_ID_DRIVE_FB_BASE + 1U,
                             FW_CAN_ID_DRIVE_FB_BASE + 2U, FW_CAN_ID_WIRES};
    for (size_t i = 0U; i < 4U; ++i) {
        setup_world(SIM_FIXTURE_RIGID);
        init_can_ctrl();
        const double q[3] = {0.3, 1.2, -0.8};
        run_ticks(300U); /* holding the arm against gravity: the drives are driving */
        int driving = 0;
        for (size_t j = 0U; j < 3U; ++j) {
            driving |= can_plant.dac[j] != DHS_DAC_ZERO;
        }
        TEST_ASSERT_TRUE(driving);
        TEST_ASSERT_EQUAL(DHC_OK, dhs_bus_drop_next(&bus, ids[i], 1U));
        TEST_ASSERT_EQUAL(FW_FAULT_PORT_TIMEOUT, fw_ctrl_move_to(&can_ctrl, q, NULL));
        TEST_ASSERT_EQUAL_UINT32(1U, bus.dropped);
        TEST_ASSERT_EQUAL_UINT32(1U, link.counters.lost);
        TEST_ASSERT_EQUAL_UINT32(1U, link.counters.timeouts);
        assert_commands_sent_zero();
        assert_plant_drives_zero();
        /* latched: nothing more is commanded */
        const uint32_t sent = mem.cmds_sent;
        TEST_ASSERT_EQUAL(FW_FAULT_PORT_TIMEOUT, fw_ctrl_move_to(&can_ctrl, q_start, NULL));
        TEST_ASSERT_EQUAL_UINT32(sent, mem.cmds_sent);
    }
}

static void test_a_late_frame_is_counted_and_not_used(void)
{
    run_ticks(20U);
    /* Before the nodes answer SYNC 30, an answer to SYNC 29 arrives with an encoder value
     * 5000 counts off: used, it would be an encoder jump fault. */
    const fw_can_drive_fb stale = {
        (uint16_t)(link.fb[1].encoder_counts + 5000U), 2048U, 1U, 0U, 0U, 29U};
    TEST_ASSERT_EQUAL(FW_CAN_MSG_OK, fw_can_encode_drive_fb(1U, &stale, &mem.inject[0]));
    mem.n_inject = 1U;
    mem.inject_at_sync = 31U; /* SYNC 0 (start) is the first one sent */
    run_ticks(20U);
    TEST_ASSERT_EQUAL_UINT32(1U, link.counters.late);
    TEST_ASSERT_EQUAL_UINT32(0U, link.counters.lost);
    TEST_ASSERT_EQUAL_UINT64(41U, link.counters.complete);
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, can_ctrl.fault);
}

static void test_a_frame_held_back_a_tick_times_out_then_is_discarded_as_late(void)
{
    run_ticks(10U);
    TEST_ASSERT_EQUAL(DHC_OK, dhs_bus_delay_next(&bus, FW_CAN_ID_DRIVE_FB_BASE + 2U, 1U));
    uint64_t t_us = 0U;
    TEST_ASSERT_EQUAL(FW_PORT_ERR_TIMEOUT, can_port.wait_tick(can_port.ctx, &t_us));
    uint16_t enc[DHC_MAX_JOINTS];
    TEST_ASSERT_EQUAL(FW_PORT_ERR_TIMEOUT, can_port.read_encoders(can_port.ctx, enc));
    TEST_ASSERT_EQUAL_UINT32(1U, link.counters.lost);
    /* next tick: the held-back frame (tick 11) comes first, then tick 12's */
    TEST_ASSERT_EQUAL(FW_PORT_OK, can_port.wait_tick(can_port.ctx, &t_us));
    TEST_ASSERT_EQUAL_UINT64(12000U, t_us);
    TEST_ASSERT_EQUAL_UINT32(1U, bus.delayed_sent);
    TEST_ASSERT_EQUAL_UINT32(1U, link.counters.late);
    TEST_ASSERT_EQUAL_UINT16(12U, link.fb[2].tick);
    TEST_ASSERT_EQUAL(FW_PORT_OK, can_port.read_encoders(can_port.ctx, enc));
    TEST_ASSERT_EQUAL_HEX16(dhs_plant_encoder(&can_plant, 2U), enc[2]);
}

static void test_nodes_that_stop_answering_stop_the_drives(void)
{
    run_ticks(300U);
    dhs_bus_set_silent(&bus, 1);
    const double q[3] = {0.3, 1.2, -0.8};
    TEST_ASSERT_EQUAL(FW_FAULT_PORT_TIMEOUT, fw_ctrl_move_to(&can_ctrl, q, NULL));
    TEST_ASSERT_EQUAL_UINT32(4U, link.counters.lost); /* three drives and the measurer */
    assert_commands_sent_zero();
}

static void test_overrun_and_drive_fault_are_io_faults(void)
{
    run_ticks(5U);
    mem.cap = 2U; /* the nodes' four answers cannot fit */
    TEST_ASSERT_EQUAL(FW_FAULT_PORT_IO, fw_ctrl_tick(&can_ctrl, q_start, NULL));
    TEST_ASSERT_EQUAL_UINT32(1U, link.counters.overruns);
    assert_commands_sent_zero();

    setup_world(SIM_FIXTURE_RIGID);
    init_can_ctrl();
    run_ticks(5U);
    const fw_can_drive_fb failed = {0U, 2048U, 0U, 0U, 1U, 6U};
    TEST_ASSERT_EQUAL(FW_CAN_MSG_OK, fw_can_encode_drive_fb(0U, &failed, &mem.inject[0]));
    mem.n_inject = 1U;
    mem.inject_at_sync = 7U;
    TEST_ASSERT_EQUAL(FW_FAULT_PORT_IO, fw_ctrl_tick(&can_ctrl, q_start, NULL));
    TEST_ASSERT_EQUAL_UINT32(1U, link.counters.drive_faults);
    assert_plant_drives_zero();
}

static void test_malformed_and_foreign_frames_are_ignored(void)
{
    run_ticks(5U);
    fw_can_frame *in = mem.inject;
    const fw_can_drive_fb fb = {0U, 2048U, 1U, 0U, 0U, 6U};
    TEST_ASSERT_EQUAL(FW_CAN_MSG_OK, fw_can_encode_drive_fb(0U, &fb, &in[0]));
    in[0].len = 5U; /* a wrong length */
    in[1] = in[0];
    in[1].len = 6U;
    in[1].data[3] |= 0x80U; /* a reserved bit */
    memset(&in[2], 0, sizeof in[2]);
    in[2].id = 0x7E5U; /* somebody else's frame */
    in[2].len = 1U;
    const fw_can_sync other = {6U}; /* a SYNC from another master */
    TEST_ASSERT_EQUAL(FW_CAN_MSG_OK, fw_can_encode_sync(&other, &in[3]));
    mem.n_inject = 4U;
    mem.inject_at_sync = 7U;
    run_ticks(5U);
    TEST_ASSERT_EQUAL_UINT32(2U, link.counters.malformed);
    TEST_ASSERT_EQUAL_UINT32(2U, link.counters.foreign);
    TEST_ASSERT_EQUAL_UINT32(0U, link.counters.lost);
}

static void test_a_drive_without_commands_goes_to_zero_by_itself(void)
{
    run_ticks(300U);
    uint64_t t_us = 0U;
    for (uint32_t k = 1U; k < DHS_BUS_CMD_WATCHDOG_TICKS; ++k) {
        TEST_ASSERT_EQUAL(FW_PORT_OK, can_port.wait_tick(can_port.ctx, &t_us));
        TEST_ASSERT_EQUAL_UINT8(1U, link.fb[0].enabled); /* one lost command is held */
    }
    TEST_ASSERT_EQUAL(FW_PORT_OK, can_port.wait_tick(can_port.ctx, &t_us));
    TEST_ASSERT_EQUAL(FW_PORT_OK, can_port.wait_tick(can_port.ctx, &t_us));
    assert_plant_drives_zero();
    for (size_t j = 0U; j < 3U; ++j) {
        TEST_ASSERT_EQUAL_UINT8(0U, link.fb[j].enabled);
    }
    TEST_ASSERT_EQUAL_UINT32(3U, bus.watchdog_trips);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_same_readings_and_positions_as_the_sim_port_rigid_arm);
    RUN_TEST(test_same_readings_and_positions_as_the_sim_port_every_effect);
    RUN_TEST(test_a_lost_feedback_frame_stops_the_drives);
    RUN_TEST(test_a_late_frame_is_counted_and_not_used);
    RUN_TEST(test_a_frame_held_back_a_tick_times_out_then_is_discarded_as_late);
    RUN_TEST(test_nodes_that_stop_answering_stop_the_drives);
    RUN_TEST(test_overrun_and_drive_fault_are_io_faults);
    RUN_TEST(test_malformed_and_foreign_frames_are_ignored);
    RUN_TEST(test_a_drive_without_commands_goes_to_zero_by_itself);
    return UNITY_END();
}
