/* test_dhcal_session.c - the desk library keeps no state between calls (issue 27): two
 * sessions in one process, built one after the other and used interleaved, or run in two
 * threads at once, give the reports each gives alone. The sessions are the example's
 * training rows and its held-out rows (examples/data/compliance), so their results differ;
 * each report is refine's whole JSON report (the steps, the judgement's candidates, the
 * fitted parameters, the cross-validation), compared byte for byte. */
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal_desk/dhcal_refine.h"
#include "dhcal_desk/dhcal_report.h"
#include "dhcal_desk/dhcal_session.h"
#include "unity.h"

#define MODEL DHCAL_SOURCE_DIR "/examples/data/compliance/model.json"
#define TRAIN DHCAL_SOURCE_DIR "/examples/data/compliance/train.csv"
#define HELD DHCAL_SOURCE_DIR "/examples/data/compliance/heldout.csv"

void setUp(void) {}
void tearDown(void) {}

static dhcal_model g_file;

static void open_session(dhcal_session *s, const char *rows)
{
    dhcal_error err;
    memset(&err, 0, sizeof err);
    TEST_ASSERT_EQUAL_MESSAGE(
        DHCAL_IO_OK, dhcal_session_begin(s, &g_file, MODEL, NULL, NULL, NULL, &err), err.msg);
    TEST_ASSERT_EQUAL_MESSAGE(DHCAL_IO_OK,
                              dhcal_csv_load(rows, s->model.arm.n_joints, &s->data, &err), err.msg);
    TEST_ASSERT_EQUAL_MESSAGE(DHCAL_IO_OK, dhcal_session_build_rows(s, rows, NULL, &err), err.msg);
}

/* refine on the session, its JSON report (caller frees; NULL when it failed). */
static char *refine_report(dhcal_session *s)
{
    dhcal_refine_result *res = calloc(1U, sizeof *res);
    double *row_err = calloc(s->samples.n + 1U, sizeof *row_err);
    dhcal_error err;
    memset(&err, 0, sizeof err);
    dhcal_error_stats es;
    char *text = NULL;
    if (res != NULL && row_err != NULL &&
        dhcal_run_refine(&s->model, NULL, NULL, &s->noise, s->repeatability_mm,
                         DHCAL_REFINE_MAX_STEPS, &s->samples, NULL, res, &err) == DHCAL_IO_OK &&
        dhcal_samples_errors(&res->fit.model, &s->samples, NULL, row_err, &es) == DHCAL_IO_OK) {
        cJSON *obj = cJSON_CreateObject();
        dhcal_json_fit(obj, &res->fit, &s->model, &s->samples, row_err);
        dhcal_json_refine(obj, res);
        text = cJSON_PrintUnformatted(obj);
        cJSON_Delete(obj);
    }
    free(res);
    free(row_err);
    return text;
}

typedef struct {
    dhcal_session *s;
    char *report;
} job;

static void *run(void *arg)
{
    job *j = arg;
    j->report = refine_report(j->s);
    return NULL;
}

static void test_sessions_share_nothing(void)
{
    dhcal_error err;
    memset(&err, 0, sizeof err);
    TEST_ASSERT_EQUAL_MESSAGE(DHCAL_IO_OK, dhcal_model_load(MODEL, &g_file, &err), err.msg);
    static dhcal_session a;
    static dhcal_session b;
    /* each alone: opened, refined, freed before the other is opened */
    open_session(&a, TRAIN);
    char *alone_a = refine_report(&a);
    dhcal_session_free(&a);
    open_session(&b, HELD);
    char *alone_b = refine_report(&b);
    dhcal_session_free(&b);
    TEST_ASSERT_NOT_NULL(alone_a);
    TEST_ASSERT_NOT_NULL(alone_b);
    TEST_ASSERT_TRUE_MESSAGE(strcmp(alone_a, alone_b) != 0, "the two data sets give one report");
    /* whole reports: the refine loop took a step on each (the example hides a compliance) */
    TEST_ASSERT_NOT_NULL(strstr(alone_a, "\"added\":\"joint_compliance:2\""));
    TEST_ASSERT_NOT_NULL(strstr(alone_b, "\"added\":\"joint_compliance:2\""));
    /* both open, used interleaved (b's rows allocated after a's: no cache can answer one
     * with the other's) */
    open_session(&b, HELD);
    open_session(&a, TRAIN);
    char *inter_b = refine_report(&b);
    char *inter_a = refine_report(&a);
    TEST_ASSERT_EQUAL_STRING(alone_a, inter_a);
    TEST_ASSERT_EQUAL_STRING(alone_b, inter_b);
    /* at once, in two threads */
    job ja = {&a, NULL};
    job jb = {&b, NULL};
    pthread_t ta;
    pthread_t tb;
    TEST_ASSERT_EQUAL(0, pthread_create(&ta, NULL, run, &ja));
    TEST_ASSERT_EQUAL(0, pthread_create(&tb, NULL, run, &jb));
    TEST_ASSERT_EQUAL(0, pthread_join(ta, NULL));
    TEST_ASSERT_EQUAL(0, pthread_join(tb, NULL));
    TEST_ASSERT_EQUAL_STRING(alone_a, ja.report);
    TEST_ASSERT_EQUAL_STRING(alone_b, jb.report);
    dhcal_session_free(&a);
    dhcal_session_free(&b);
    free(alone_a);
    free(alone_b);
    free(inter_a);
    free(inter_b);
    free(ja.report);
    free(jb.report);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_sessions_share_nothing);
    return UNITY_END();
}
