/* test_linux_nv.c - the file-backed calibration store of the Linux port: a new file reads
 * erased (0xFF), writes persist across close and reopen, ranges are checked, and
 * fw_calstore saves and loads a model through it. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "dhc_test_arms.h"
#include "dhcal_fw/fw_calstore.h"
#include "fw_linux_nv.h"
#include "unity.h"

#define NV_SIZE 8192U

static char path[64];

void setUp(void)
{
    (void)snprintf(path, sizeof path, "test_linux_nv.%ld.bin", (long)getpid());
    (void)remove(path);
}

void tearDown(void)
{
    (void)remove(path);
}

static void test_a_new_file_reads_erased_and_has_the_size(void)
{
    fw_linux_nv f;
    fw_nvstore nv;
    char why[128];
    TEST_ASSERT_EQUAL_INT(0, fw_linux_nv_open(&f, path, NV_SIZE, &nv, why, sizeof why));
    uint8_t buf[NV_SIZE];
    TEST_ASSERT_EQUAL_INT(FW_NV_OK, nv.read(nv.ctx, 0U, buf, sizeof buf));
    for (size_t i = 0U; i < sizeof buf; ++i) {
        TEST_ASSERT_EQUAL_HEX8(0xFF, buf[i]);
    }
    fw_linux_nv_close(&f);
    struct stat st;
    TEST_ASSERT_EQUAL_INT(0, stat(path, &st));
    TEST_ASSERT_EQUAL_INT64((long long)NV_SIZE, (long long)st.st_size);
}

static void test_writes_persist_across_reopen(void)
{
    fw_linux_nv f;
    fw_nvstore nv;
    char why[128];
    const char msg[] = "dhcal";
    TEST_ASSERT_EQUAL_INT(0, fw_linux_nv_open(&f, path, NV_SIZE, &nv, why, sizeof why));
    TEST_ASSERT_EQUAL_INT(FW_NV_OK, nv.write(nv.ctx, NV_SIZE - sizeof msg, msg, sizeof msg));
    fw_linux_nv_close(&f);
    TEST_ASSERT_EQUAL_INT(0, fw_linux_nv_open(&f, path, NV_SIZE, &nv, why, sizeof why));
    char back[sizeof msg];
    TEST_ASSERT_EQUAL_INT(FW_NV_OK, nv.read(nv.ctx, NV_SIZE - sizeof msg, back, sizeof back));
    TEST_ASSERT_EQUAL_STRING(msg, back);
    fw_linux_nv_close(&f);
}

static void test_ranges_beyond_the_region_are_refused(void)
{
    fw_linux_nv f;
    fw_nvstore nv;
    char why[128];
    uint8_t b[2] = {1U, 2U};
    TEST_ASSERT_EQUAL_INT(0, fw_linux_nv_open(&f, path, NV_SIZE, &nv, why, sizeof why));
    TEST_ASSERT_EQUAL_INT(FW_NV_ERR_RANGE, nv.write(nv.ctx, NV_SIZE - 1U, b, 2U));
    TEST_ASSERT_EQUAL_INT(FW_NV_ERR_RANGE, nv.read(nv.ctx, NV_SIZE + 1U, b, 0U));
    TEST_ASSERT_EQUAL_INT(FW_NV_ERR_RANGE, nv.read(nv.ctx, 1U, b, (size_t)-1));
    fw_linux_nv_close(&f);
}

static void test_a_directory_is_not_a_store(void)
{
    fw_linux_nv f;
    fw_nvstore nv;
    char why[128] = "";
    TEST_ASSERT_EQUAL_INT(-1, fw_linux_nv_open(&f, ".", NV_SIZE, &nv, why, sizeof why));
    TEST_ASSERT_TRUE(strlen(why) > 0U);
}

static void test_the_calibration_store_round_trips_through_the_file(void)
{
    fw_linux_nv f;
    fw_nvstore nv;
    char why[128];
    dhc_model m = test_paper3_model();
    m.arm.joint[1].a_mm += 0.25;
    TEST_ASSERT_EQUAL_INT(0, fw_linux_nv_open(&f, path, NV_SIZE, &nv, why, sizeof why));
    uint32_t seq = 0U;
    TEST_ASSERT_EQUAL_INT(FW_CAL_OK, fw_cal_save(&nv, &m, &seq));
    fw_linux_nv_close(&f);
    TEST_ASSERT_EQUAL_INT(0, fw_linux_nv_open(&f, path, NV_SIZE, &nv, why, sizeof why));
    dhc_model back;
    uint32_t seq_back = 0U;
    TEST_ASSERT_EQUAL_INT(FW_CAL_OK, fw_cal_load(&nv, &back, &seq_back));
    TEST_ASSERT_EQUAL_UINT32(seq, seq_back);
    TEST_ASSERT_EQUAL_DOUBLE(m.arm.joint[1].a_mm, back.arm.joint[1].a_mm);
    fw_linux_nv_close(&f);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_a_new_file_reads_erased_and_has_the_size);
    RUN_TEST(test_writes_persist_across_reopen);
    RUN_TEST(test_ranges_beyond_the_region_are_refused);
    RUN_TEST(test_a_directory_is_not_a_store);
    RUN_TEST(test_the_calibration_store_round_trips_through_the_file);
    return UNITY_END();
}
