/* job_replay.c - the controller's job (fw_job) on recorded samples, the same on the
 * Cortex-M4 and on the host (twin.h):
 *   job_replay FILE [configured|diagnose|live|touch]
 * FILE: wire samples of the paper's 3-DOF arm as dhcal-demo collected them. The job boots
 * on a port whose arm stands still at the start pose (nothing moves: the samples are
 * recorded), plans, takes the recording as its acquisition (fw_job_acquire_recorded),
 * calibrates with the demo's configuration (noise model on, the diagnosis when the library
 * has it; with `diagnose`, the diagnosis asked for in any case; with `configured`, as
 * `dhcal-demo --effects joint_compliance:2 --no-diagnose`: the effect known and fitted from
 * the start, no diagnosis) and stores
 * into a RAM store through fw_calstore. Prints what the job found, the parameters of the
 * calibration it stored (read back with fw_cal_load), the store's bytes, the angles the
 * controller's inverse kinematics (fw_ik) commands for three points on the stored model and
 * the instructions fw_job_calibrate took (0 on the host). `live`: the job acquires through
 * the port (fw_job_acquire), whose arm never moves: the controller must stop with a fault,
 * drives at zero, before it takes a sample. So the program holds everything a controller
 * runs: its linked bytes are the controller's flash for the library (scripts/target-report).
 * `touch`: FILE holds the touches dhcal-touch-demo's controller took (planes and gauge
 * lengths, twin.h's version 2); the job calibrates the arm with the planes' poses from them
 * (no noise model, no diagnosis, as dhcal-touch-demo) and prints the planes it found too. */
#include <string.h>

#include "dhc_test_arms.h"
#include "dhcal/dhc_params.h"
#include "dhcal_fw/fw_calstore.h"
#include "dhcal_fw/fw_ik.h"
#include "dhcal_fw/fw_job.h"
#include "twin.h"

/* ---- the port: an arm standing still, counters at zero, a store in RAM */

static uint64_t now_us;
static uint8_t nv_bytes[2U * FW_CAL_SLOT_SIZE];

static fw_port_status still_tick(void *ctx, uint64_t *t_us)
{
    (void)ctx;
    now_us += 1000U;
    *t_us = now_us;
    return FW_PORT_OK;
}

static fw_port_status still_encoders(void *ctx, uint16_t counts[DHC_MAX_JOINTS])
{
    (void)ctx;
    memset(counts, 0, DHC_MAX_JOINTS * sizeof counts[0]);
    return FW_PORT_OK;
}

static fw_port_status still_tachos(void *ctx, uint16_t codes[DHC_MAX_JOINTS])
{
    (void)ctx;
    for (size_t j = 0U; j < DHC_MAX_JOINTS; ++j) {
        codes[j] = 2048U; /* 0 V: not turning */
    }
    return FW_PORT_OK;
}

static fw_port_status still_dacs(void *ctx, const uint16_t codes[DHC_MAX_JOINTS])
{
    (void)ctx;
    (void)codes;
    return FW_PORT_OK;
}

static fw_port_status still_wires(void *ctx, uint16_t counts[3])
{
    (void)ctx;
    memset(counts, 0, 3U * sizeof counts[0]);
    return FW_PORT_OK;
}

static fw_nv_status ram_read(void *ctx, size_t offset, void *buf, size_t len)
{
    (void)ctx;
    if (offset > sizeof nv_bytes || len > sizeof nv_bytes - offset) {
        return FW_NV_ERR_RANGE;
    }
    memcpy(buf, nv_bytes + offset, len);
    return FW_NV_OK;
}

static fw_nv_status ram_write(void *ctx, size_t offset, const void *buf, size_t len)
{
    (void)ctx;
    if (offset > sizeof nv_bytes || len > sizeof nv_bytes - offset) {
        return FW_NV_ERR_RANGE;
    }
    memcpy(nv_bytes + offset, buf, len);
    return FW_NV_OK;
}

/* ---- the job */

static dhc_sample recorded[TWIN_MAX_SAMPLES];
static fw_job job;
static dhc_model stored;

/* The demo arm's machine (host_sim/scenarios/joint_compliance_2.json): 500-line encoders
 * decoded x4 on the motors, 100:1 gears, the measurer's 10 mm wheels with 1000 lines x4. */
static void paper_arm_io(fw_io_config *io)
{
    memset(io, 0, sizeof *io);
    for (size_t j = 0U; j < 3U; ++j) {
        fw_io_set_joint(io, j, 2000.0, 100.0, 0.029);
    }
    io->adc_v_full_scale = 10.0;
    io->dac_v_full_scale = 10.0;
    fw_io_set_wires(io, 10.0, 4000.0, NULL);
}

static void put_store(void)
{
    for (size_t off = 0U; off < sizeof nv_bytes; off += 64U) {
        twin_puts("store ");
        for (size_t i = off; i < off + 64U && i < sizeof nv_bytes; ++i) {
            twin_putchar("0123456789abcdef"[nv_bytes[i] >> 4]);
            twin_putchar("0123456789abcdef"[nv_bytes[i] & 0xFU]);
        }
        twin_putchar('\n');
    }
}

int twin_main(int argc, char **argv)
{
    size_t n = 0U;
    size_t nj = 0U;
    const int configured = argc == 3 && strcmp(argv[2], "configured") == 0;
    const int diagnose = argc == 3 && strcmp(argv[2], "diagnose") == 0;
    const int live = argc == 3 && strcmp(argv[2], "live") == 0;
    const int touch = argc == 3 && strcmp(argv[2], "touch") == 0;
    if ((argc != 2 && !configured && !diagnose && !live && !touch) ||
        twin_load_samples(argv[1], recorded, TWIN_MAX_SAMPLES, &n, &nj) != 0 || nj != 3U) {
        twin_puts("usage: job_replay FILE [configured|diagnose|live|touch] (wire samples, or "
                  "touches, of the 3-DOF paper arm)\n");
        return 2;
    }
    dhc_model nominal = test_paper3_model();
    test_put_paper_measurer(&nominal);
    static fw_io_config io;
    paper_arm_io(&io);
    static fw_port port;
    port.n_joints = 3U;
    port.wait_tick = still_tick;
    port.read_encoders = still_encoders;
    port.read_tachos = still_tachos;
    port.write_dacs = still_dacs;
    port.read_wires = still_wires;
    port.nv.size = sizeof nv_bytes;
    port.nv.read = ram_read;
    port.nv.write = ram_write;

    /* dhcal-demo's configuration of the job */
    fw_job_config cfg;
    fw_job_default_config(&cfg, &nominal);
    cfg.q_start_rad[1] = 60.0 * DHC_PI / 180.0;
    cfg.q_start_rad[2] = -60.0 * DHC_PI / 180.0;
    cfg.n_samples = n;
    cfg.noise_model = 1;
    /* the wires' noise the demo measured over its holds; the recording has no holds */
    cfg.autocal.wire_noise_mm = 0.0036;
    if (configured) {
        cfg.autocal.n_effects = 1U;
        cfg.autocal.effect[0] = DHC_EFFECT_JOINT_COMPLIANCE;
        cfg.autocal.effect_joint[0] = 1U;
        cfg.autocal.diagnose = 0;
    }
    if (diagnose) {
        cfg.autocal.diagnose = 1; /* whatever the build's default */
    }
    if (touch) {
        cfg.noise_model = 0;
        cfg.autocal.diagnose = 0;
    }

    fw_fault f = fw_job_boot(&job, &cfg, &nominal, &port, &io);
    if (f == FW_FAULT_NONE && !touch) {
        f = fw_job_plan(&job);
    }
    if (f == FW_FAULT_NONE) {
        f = live ? fw_job_acquire(&job) : fw_job_acquire_recorded(&job, recorded, n, NULL);
    }
    uint64_t took = 0U;
    if (f == FW_FAULT_NONE) {
        const uint64_t t0 = twin_instructions();
        twin_measure_begin();
        f = fw_job_calibrate(&job, &port.nv);
        twin_measure_end();
        took = twin_instructions() - t0;
    }
    twin_puts("fault ");
    twin_puts(fw_fault_name(f));
    twin_puts("\nsamples ");
    twin_put_u64(job.n_samples);
    twin_putchar('\n');
    twin_put_double("o1", job.o1);
    if (f != FW_FAULT_NONE) {
        return 1;
    }
    /* Keys by number, not name: the program links what a controller links (it names no
     * parameter and no effect; the desk does), so its map measures the controller's flash. */
    const fw_autocal_result *r = &job.result;
    twin_puts("diagnosis ");
    twin_put_u64((uint64_t)r->diagnosis);
    twin_puts("\nfound ");
    twin_put_u64((uint64_t)r->found);
    twin_puts("\neffect ");
    twin_put_u64(r->found ? (uint64_t)r->effect * 100U + r->effect_joint : 0U);
    twin_puts("\nsaved ");
    twin_put_u64((uint64_t)r->saved);
    twin_puts("\ngeo_rank ");
    twin_put_u64(r->geo.rank);
    twin_putchar('\n');
    twin_put_double("geo_rms_mm", r->geo.rms_mm);
    twin_put_double("effect_log10_p", r->effect_log10_p);
    twin_put_double("final_rms_mm", r->new_rms_mm);
    uint32_t seq = 0U;
    if (fw_cal_load(&port.nv, &stored, &seq) != FW_CAL_OK) {
        twin_puts("error: nothing stored\n");
        return 1;
    }
    twin_puts("seq ");
    twin_put_u64(seq);
    twin_putchar('\n');
    dhc_param_set set;
    if (fw_job_param_set(&job, &set) != DHC_OK) {
        twin_puts("error: no parameter set\n");
        return 1;
    }
    for (size_t k = 0U; k < set.count; ++k) {
        char key[8] = "p.00"; /* the parameter's index in the job's set (fw_job_param_set) */
        key[2] = (char)('0' + (int)(k / 10U));
        key[3] = (char)('0' + (int)(k % 10U));
        twin_put_double(key, dhc_params_value(&set, &stored, k));
    }
    for (size_t k = 0U; touch && k < job.calibrated.contact.n_planes; ++k) {
        char key[16] = "plane0.n0";
        key[5] = (char)('0' + (int)k);
        for (size_t c = 0U; c < 3U; ++c) {
            key[8] = (char)('0' + (int)c);
            twin_put_double(key, job.calibrated.contact.plane[k].normal[c]);
        }
        char off[16] = "plane0.offset";
        off[5] = (char)('0' + (int)k);
        twin_put_double(off, job.calibrated.contact.plane[k].offset_mm);
    }
    put_store();
    /* What the controller does with the calibration: points moved to on the stored model
     * (fw_ik, the library's inverse kinematics through the effects), 3 mm off the tool
     * points of three recorded poses, from those poses' angles. */
    const double shift[3] = {3.0, -2.0, 3.0};
    for (size_t k = 0U; k < 3U; ++k) {
        const dhc_sample *at = &recorded[k * (n - 1U) / 2U];
        double target[3];
        double q[DHC_MAX_JOINTS];
        memcpy(q, at->q_rad, sizeof q);
        if (dhc_model_tool_point(&stored, at->q_rad, at->dir, target) != DHC_OK) {
            twin_puts("error: no tool point\n");
            return 1;
        }
        for (size_t c = 0U; c < 3U; ++c) {
            target[c] += shift[c];
        }
        char key[16] = "ik0";
        key[2] = (char)('0' + (int)k);
        twin_puts(key);
        twin_puts(fw_ik_solve(&stored, at, target, 1e-6, 50U, q) == FW_IK_OK ? " ok\n"
                                                                             : " failed\n");
        for (size_t j = 0U; j < 3U; ++j) {
            char qkey[16] = "ik0.q0";
            qkey[2] = (char)('0' + (int)k);
            qkey[5] = (char)('1' + (int)j);
            twin_put_double(qkey, q[j]);
        }
    }
    twin_puts("instructions ");
    twin_put_u64(took);
    twin_putchar('\n');
    return 0;
}
