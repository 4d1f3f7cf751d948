/* test_dhcal_units.c - the units check's similarity fit (tools/dhcal/dhcal_units.h) against
 * independent computations: clouds made with a known rotation, scale and shift; the optimal
 * alignment's value against the singular values of the cross-covariance, computed here in
 * closed form (the eigenvalues of S^T S by the trigonometric solution of the cubic), not by
 * Horn's quaternion matrix; and no rotation tried at random does better. Then the check
 * itself on a small arm: a dataset from its own forward kinematics passes, and the same data
 * in metres, in radians, with two joint columns or two coordinates exchanged, or in a
 * turned and shifted frame are refused with the cause named. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "dhcal/dhc_geometry.h"
#include "dhcal/dhc_model.h"
#include "dhcal_desk/dhcal_units.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

enum { N = 40 };

/* A deterministic cloud spread over a metre, not flat. */
static void cloud(double *a, size_t n)
{
    unsigned long s = 12345UL;
    for (size_t i = 0U; i < 3U * n; ++i) {
        s = (s * 1103515245UL + 12345UL) % 2147483648UL;
        a[i] = ((double)s / 2147483648.0 - 0.5) * (i % 3U == 2U ? 600.0 : 1000.0);
    }
}

/* R = exp([axis angle]) by Rodrigues' formula, written out here. */
static void rodrigues(const double axis[3], double angle, double r[3][3])
{
    const double n = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    const double k[3] = {axis[0] / n, axis[1] / n, axis[2] / n};
    const double c = cos(angle);
    const double s = sin(angle);
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            r[i][j] = (1.0 - c) * k[i] * k[j] + (i == j ? c : 0.0);
        }
    }
    r[0][1] -= s * k[2];
    r[0][2] += s * k[1];
    r[1][0] += s * k[2];
    r[1][2] -= s * k[0];
    r[2][0] -= s * k[1];
    r[2][1] += s * k[0];
}

static void transform(const double *a, size_t n, double r[3][3], double scale, const double t[3],
                      double *b)
{
    for (size_t i = 0U; i < n; ++i) {
        for (int k = 0; k < 3; ++k) {
            b[3U * i + (size_t)k] = scale * (r[k][0] * a[3U * i] + r[k][1] * a[3U * i + 1U] +
                                             r[k][2] * a[3U * i + 2U]) +
                                    t[k];
        }
    }
}

static void test_a_known_rotation_scale_and_shift_is_recovered(void)
{
    static double a[3 * N];
    static double b[3 * N];
    cloud(a, N);
    const double axis[3] = {0.3, -0.5, 0.8};
    double r[3][3];
    rodrigues(axis, 2.1, r); /* 120 deg: far from the identity */
    const double t[3] = {1500.0, -800.0, 300.0};
    transform(a, N, r, 1000.0, t, b); /* b in mm, a "in metres" read as mm */
    dhcal_similarity f;
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_similarity_fit(a, b, N, 0, &f));
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 1000.0, f.scale);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 1.0, f.corr);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 2.1 / DHC_DEG, f.turn_deg);
    for (int i = 0; i < 3; ++i) {
        TEST_ASSERT_DOUBLE_WITHIN(1e-6, t[i], f.shift[i]);
        for (int j = 0; j < 3; ++j) {
            TEST_ASSERT_DOUBLE_WITHIN(1e-12, r[i][j], f.rot[i][j]);
        }
    }
    TEST_ASSERT_TRUE(f.rms_similarity < 1e-6);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 1000.0, f.spread_b / f.spread_a);
    /* the rigid fit cannot take the scale: it leaves about the whole cloud */
    TEST_ASSERT_TRUE(f.rms_rigid > 0.99 * f.spread_b);
}

/* The eigenvalues of a symmetric 3x3 matrix, largest first (Smith's closed form). */
static void sym3_eigenvalues(double m[3][3], double ev[3])
{
    const double p1 = m[0][1] * m[0][1] + m[0][2] * m[0][2] + m[1][2] * m[1][2];
    const double q = (m[0][0] + m[1][1] + m[2][2]) / 3.0;
    const double p2 = (m[0][0] - q) * (m[0][0] - q) + (m[1][1] - q) * (m[1][1] - q) +
                      (m[2][2] - q) * (m[2][2] - q) + 2.0 * p1;
    const double p = sqrt(p2 / 6.0);
    double bm[3][3];
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            bm[i][j] = (m[i][j] - (i == j ? q : 0.0)) / p;
        }
    }
    const double det = bm[0][0] * (bm[1][1] * bm[2][2] - bm[1][2] * bm[2][1]) -
                       bm[0][1] * (bm[1][0] * bm[2][2] - bm[1][2] * bm[2][0]) +
                       bm[0][2] * (bm[1][0] * bm[2][1] - bm[1][1] * bm[2][0]);
    const double phi = acos(fmax(-1.0, fmin(1.0, det / 2.0))) / 3.0;
    ev[0] = q + 2.0 * p * cos(phi);
    ev[2] = q + 2.0 * p * cos(phi + 2.0 * DHC_PI / 3.0);
    ev[1] = 3.0 * q - ev[0] - ev[2];
}

/* max over rotations of sum b . R a = s1 + s2 + sign(det S) s3 (S's singular values), and
 * over improper rotations s1 + s2 - sign(det S) s3: the correlation both ways. */
static void procrustes_by_svd(const double *a, const double *b, size_t n, double *proper,
                              double *improper)
{
    double ca[3] = {0.0, 0.0, 0.0};
    double cb[3] = {0.0, 0.0, 0.0};
    for (size_t i = 0U; i < n; ++i) {
        for (size_t k = 0U; k < 3U; ++k) {
            ca[k] += a[3U * i + k] / (double)n;
            cb[k] += b[3U * i + k] / (double)n;
        }
    }
    double s[3][3] = {{0.0}};
    double saa = 0.0;
    double sbb = 0.0;
    for (size_t i = 0U; i < n; ++i) {
        for (size_t r = 0U; r < 3U; ++r) {
            saa += (a[3U * i + r] - ca[r]) * (a[3U * i + r] - ca[r]);
            sbb += (b[3U * i + r] - cb[r]) * (b[3U * i + r] - cb[r]);
            for (size_t c = 0U; c < 3U; ++c) {
                s[r][c] += (a[3U * i + r] - ca[r]) * (b[3U * i + c] - cb[c]);
            }
        }
    }
    double sts[3][3];
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            sts[i][j] = s[0][i] * s[0][j] + s[1][i] * s[1][j] + s[2][i] * s[2][j];
        }
    }
    double ev[3];
    sym3_eigenvalues(sts, ev);
    const double det = s[0][0] * (s[1][1] * s[2][2] - s[1][2] * s[2][1]) -
                       s[0][1] * (s[1][0] * s[2][2] - s[1][2] * s[2][0]) +
                       s[0][2] * (s[1][0] * s[2][1] - s[1][1] * s[2][0]);
    const double sv[3] = {sqrt(fmax(0.0, ev[0])), sqrt(fmax(0.0, ev[1])), sqrt(fmax(0.0, ev[2]))};
    const double sg = det >= 0.0 ? 1.0 : -1.0;
    *proper = (sv[0] + sv[1] + sg * sv[2]) / sqrt(saa * sbb);
    *improper = (sv[0] + sv[1] - sg * sv[2]) / sqrt(saa * sbb);
}

static void test_noisy_clouds_agree_with_the_singular_values(void)
{
    static double a[3 * N];
    static double b[3 * N];
    static double noise[3 * N];
    cloud(a, N);
    const double axis[3] = {-0.2, 0.9, 0.1};
    double r[3][3];
    rodrigues(axis, -0.7, r);
    const double t[3] = {10.0, 20.0, -30.0};
    transform(a, N, r, 1.0, t, b);
    cloud(noise, N); /* the same generator, shifted: a second, unrelated cloud */
    for (size_t i = 0U; i < 3U * N; ++i) {
        b[i] += 0.05 * noise[(i + 7U) % (3U * N)];
    }
    dhcal_similarity f;
    dhcal_similarity m;
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_similarity_fit(a, b, N, 0, &f));
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_similarity_fit(a, b, N, 1, &m));
    double proper = 0.0;
    double improper = 0.0;
    procrustes_by_svd(a, b, N, &proper, &improper);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, proper, f.corr);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, improper, m.corr);
    TEST_ASSERT_TRUE(m.corr < 0.9 * f.corr); /* the mirror image does not fit */
    /* the residuals as stated: spread_b sqrt(1 - corr^2), and the rigid one from its own
     * optimum, sum |a|^2 + sum |b|^2 - 2 lambda */
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, f.spread_b * sqrt(1.0 - f.corr * f.corr), f.rms_similarity);
    const double rigid = sqrt(f.spread_a * f.spread_a + f.spread_b * f.spread_b -
                              2.0 * f.corr * f.spread_a * f.spread_b);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, rigid, f.rms_rigid);
    /* no rotation near the answer or anywhere else aligns better */
    unsigned long s = 99UL;
    for (int k = 0; k < 200; ++k) {
        double ax[3];
        for (int j = 0; j < 3; ++j) {
            s = (s * 1103515245UL + 12345UL) % 2147483648UL;
            ax[j] = (double)s / 2147483648.0 - 0.5;
        }
        double rr[3][3];
        rodrigues(ax, k < 100 ? 1e-3 * (double)(k + 1) : 0.05 * (double)k, rr);
        double rt[3][3];
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j) {
                rt[i][j] = rr[i][0] * f.rot[0][j] + rr[i][1] * f.rot[1][j] + rr[i][2] * f.rot[2][j];
            }
        }
        static double c[3 * N];
        const double zero[3] = {0.0, 0.0, 0.0};
        transform(a, N, rt, f.scale, zero, c);
        double cc[3] = {0.0, 0.0, 0.0};
        double cbm[3] = {0.0, 0.0, 0.0};
        for (size_t i = 0U; i < N; ++i) {
            for (size_t j = 0U; j < 3U; ++j) {
                cc[j] += c[3U * i + j] / N;
                cbm[j] += b[3U * i + j] / N;
            }
        }
        double sum = 0.0;
        for (size_t i = 0U; i < N; ++i) {
            for (size_t j = 0U; j < 3U; ++j) {
                const double d = b[3U * i + j] - cbm[j] - (c[3U * i + j] - cc[j]);
                sum += d * d;
            }
        }
        TEST_ASSERT_TRUE(sqrt(sum / N) >= f.rms_similarity * (1.0 - 1e-12));
    }
}

static void test_a_mirror_image_fits_only_mirrored(void)
{
    static double a[3 * N];
    static double b[3 * N];
    cloud(a, N);
    double r[3][3];
    const double axis[3] = {1.0, 1.0, 0.0};
    rodrigues(axis, 0.4, r);
    const double t[3] = {0.0, 0.0, 0.0};
    transform(a, N, r, 1.0, t, b);
    for (size_t i = 0U; i < N; ++i) { /* x and y exchanged: a reflection */
        const double x = a[3U * i];
        a[3U * i] = a[3U * i + 1U];
        a[3U * i + 1U] = x;
    }
    dhcal_similarity f;
    dhcal_similarity m;
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_similarity_fit(a, b, N, 0, &f));
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_similarity_fit(a, b, N, 1, &m));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 1.0, m.corr);
    TEST_ASSERT_TRUE(f.corr < 0.9);
}

static void test_clouds_without_spread_are_refused(void)
{
    double a[9] = {1.0, 2.0, 3.0, 1.0, 2.0, 3.0, 1.0, 2.0, 3.0};
    double b[9] = {0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0};
    dhcal_similarity f;
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_FAILED, dhcal_similarity_fit(a, b, 3U, 0, &f));
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_FAILED, dhcal_similarity_fit(a, b, 0U, 0, &f));
}

/* ---------------------------------------------------------------- the check on an arm */

/* The paper's 3-joint arm (examples/models/paper-3dof.json), no measurer. */
static void arm(dhc_model *m)
{
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_model_init(m, 3U));
    const double alpha[3] = {90.0, 0.0, 0.0};
    const double a[3] = {0.0, 400.0, 345.0};
    const double d[3] = {433.0, 0.0, 0.0};
    for (size_t j = 0U; j < 3U; ++j) {
        m->arm.joint[j].alpha_rad = alpha[j] * DHC_DEG;
        m->arm.joint[j].a_mm = a[j];
        m->arm.joint[j].d_mm = d[j];
        m->arm.joint[j].min_rad = -170.0 * DHC_DEG;
        m->arm.joint[j].max_rad = 170.0 * DHC_DEG;
    }
}

/* Rows at spread angles with the arm's own tool points. */
static void rows(const dhc_model *m, dhcal_row *r, size_t n)
{
    memset(r, 0, n * sizeof *r);
    for (size_t i = 0U; i < n; ++i) {
        r[i].line = i + 2U;
        r[i].q_rad[0] = (-150.0 + 300.0 * (double)((i * 7U) % n) / (double)n) * DHC_DEG;
        r[i].q_rad[1] = (10.0 + 140.0 * (double)((i * 11U) % n) / (double)n) * DHC_DEG;
        r[i].q_rad[2] = (-120.0 + 200.0 * (double)((i * 13U) % n) / (double)n) * DHC_DEG;
        TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_model_tool_point(m, r[i].q_rad, NULL, r[i].xyz_mm));
    }
}

static int check(const dhc_model *m, dhcal_row *r, const char *effects, const char *cause)
{
    dhcal_dataset d;
    memset(&d, 0, sizeof d);
    d.n_rows = N;
    d.n_joints = 3U;
    d.has_xyz = 1;
    d.has_q = 1;
    d.rows = r;
    const dhcal_units_ask ask = {effects, 1, "go on", "base_frame"};
    dhcal_error err;
    memset(&err, 0, sizeof err);
    dhcal_units_report rep;
    const int rc = dhcal_units_check(m, &d, "D.csv", &ask, &rep, &err);
    if (cause == NULL) {
        TEST_ASSERT_EQUAL_INT_MESSAGE(DHCAL_IO_OK, rc, err.msg);
    } else {
        TEST_ASSERT_EQUAL_INT_MESSAGE(DHCAL_IO_BAD_INPUT, rc, err.msg);
        TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err.msg, cause), err.msg);
        TEST_ASSERT_EQUAL_INT(0, strncmp(err.msg, "D.csv: ", 7U));
        TEST_ASSERT_NOT_NULL(strstr(err.msg, "; go on"));
    }
    return rc;
}

static void test_the_check_names_each_mistake(void)
{
    static dhc_model m;
    arm(&m);
    static dhcal_row r[N];
    rows(&m, r, N);
    (void)check(&m, r, NULL, NULL);
    for (size_t i = 0U; i < N; ++i) {
        for (size_t k = 0U; k < 3U; ++k) {
            r[i].xyz_mm[k] /= 1000.0;
        }
    }
    (void)check(&m, r, NULL, "positions look like metres");
    rows(&m, r, N);
    for (size_t i = 0U; i < N; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            r[i].q_rad[j] *= DHC_DEG; /* the radians' numbers read as degrees */
        }
    }
    (void)check(&m, r, NULL, "joint angles look like radians");
    rows(&m, r, N);
    for (size_t i = 0U; i < N; ++i) {
        const double q = r[i].q_rad[1];
        r[i].q_rad[1] = r[i].q_rad[2];
        r[i].q_rad[2] = q;
    }
    (void)check(&m, r, NULL, "columns q2 and q3 look swapped");
    rows(&m, r, N);
    for (size_t i = 0U; i < N; ++i) {
        const double x = r[i].xyz_mm[0];
        r[i].xyz_mm[0] = r[i].xyz_mm[2];
        r[i].xyz_mm[2] = x;
    }
    (void)check(&m, r, NULL, "columns x and z look swapped");
    rows(&m, r, N);
    double turn[3][3];
    const double axis[3] = {0.0, 0.0, 1.0};
    rodrigues(axis, 0.6, turn);
    for (size_t i = 0U; i < N; ++i) {
        double p[3];
        memcpy(p, r[i].xyz_mm, sizeof p);
        for (int k = 0; k < 3; ++k) {
            r[i].xyz_mm[k] =
                turn[k][0] * p[0] + turn[k][1] * p[1] + turn[k][2] * p[2] + (k == 0 ? 2000.0 : 0.0);
        }
    }
    (void)check(&m, r, NULL, "another frame");
    (void)check(&m, r, "tool_offset,base_frame", NULL);
}

/* Touch rows (docs/formats.md 3.4) measure no point: mixed among measured rows, every third
 * row a touch with its points left at 0, the check judges the measured rows alone (with the
 * touches' zeros it would see another frame or unit), and still names metres. */
static void test_touch_rows_are_not_measurements(void)
{
    static dhc_model m;
    arm(&m);
    static dhcal_row r[N];
    rows(&m, r, N);
    for (size_t i = 0U; i < N; i += 3U) {
        memset(r[i].xyz_mm, 0, sizeof r[i].xyz_mm);
        r[i].plane = 1U;
    }
    (void)check(&m, r, NULL, NULL);
    for (size_t i = 0U; i < N; ++i) {
        for (size_t k = 0U; k < 3U; ++k) {
            r[i].xyz_mm[k] /= 1000.0;
        }
    }
    (void)check(&m, r, NULL, "positions look like metres");
}

/* One joint swept, the others still, on an arm a millimetre off the model: an arc, which
 * an exchange with a still column only moves onto another axis, where a similarity matches
 * it as well. Neither a swap nor another unit or frame. */
static void test_a_single_joint_sweep_is_no_swap(void)
{
    static dhc_model m;
    static dhc_model truth;
    arm(&m);
    arm(&truth);
    truth.arm.joint[1].a_mm += 1.0;
    truth.arm.joint[0].d_mm -= 0.7;
    static dhcal_row r[N];
    memset(r, 0, sizeof r);
    for (size_t i = 0U; i < N; ++i) {
        r[i].q_rad[0] = 0.3;
        r[i].q_rad[1] = (20.0 + 120.0 * (double)i / (double)N) * DHC_DEG;
        r[i].q_rad[2] = -0.5;
        TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_model_tool_point(&truth, r[i].q_rad, NULL, r[i].xyz_mm));
    }
    (void)check(&m, r, NULL, NULL);
}

static void test_a_model_in_metres_is_named(void)
{
    static dhc_model m;
    arm(&m);
    for (size_t j = 0U; j < 3U; ++j) {
        m.arm.joint[j].a_mm /= 1000.0;
        m.arm.joint[j].d_mm /= 1000.0;
    }
    dhcal_error err;
    memset(&err, 0, sizeof err);
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_BAD_INPUT, dhcal_units_check_model(&m, "M.json", NULL, &err));
    TEST_ASSERT_NOT_NULL(strstr(err.msg, "M.json: the model's lengths look like metres"));
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_BAD_INPUT,
                          dhcal_units_check_height(&m, "M.json", -HUGE_VAL, "--min-z", NULL, &err));
    arm(&m);
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK,
                          dhcal_units_check_height(&m, "M.json", -HUGE_VAL, "--min-z", NULL, &err));
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK,
                          dhcal_units_check_height(&m, "M.json", 0.0, "--min-z", NULL, &err));
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK,
                          dhcal_units_check_height(&m, "M.json", 300.0, "--min-z", NULL, &err));
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_BAD_INPUT,
                          dhcal_units_check_height(&m, "M.json", 0.3, "--min-z", NULL, &err));
    TEST_ASSERT_NOT_NULL(strstr(err.msg, "--min-z 0.3 looks like metres"));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_a_known_rotation_scale_and_shift_is_recovered);
    RUN_TEST(test_noisy_clouds_agree_with_the_singular_values);
    RUN_TEST(test_a_mirror_image_fits_only_mirrored);
    RUN_TEST(test_clouds_without_spread_are_refused);
    RUN_TEST(test_the_check_names_each_mistake);
    RUN_TEST(test_touch_rows_are_not_measurements);
    RUN_TEST(test_a_single_joint_sweep_is_no_swap);
    RUN_TEST(test_a_model_in_metres_is_named);
    return UNITY_END();
}
