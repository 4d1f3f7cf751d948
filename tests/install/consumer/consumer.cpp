// A C++ program outside the dhcal tree, built against the installed package: once with
// find_package(dhcal CONFIG) (CMakeLists.txt beside it) and once with pkg-config
// (tests/install/check_install.sh). It proves that the headers are usable from C++, that
// dhcal::dhcal / dhcal.pc carry everything needed to link, and that the library works:
//   1. forward kinematics of a planar two-link arm equals the closed form
//      x = a1 cos q1 + a2 cos(q1 + q2), y = a1 sin q1 + a2 sin(q1 + q2);
//   2. a calibration from exact measurements of a "true" arm (link 1 is 1.5 mm long, joint
//      2 is 0.01 rad off) predicts that arm's closed-form tool point at new angles.
#include <cmath>
#include <cstdio>
#include <cstring>

#include <dhcal/dhcal.h>

namespace
{

constexpr double kA1 = 300.0;
constexpr double kA2 = 200.0;

int failures = 0;

void check(bool ok, const char *what, double got, double want)
{
    if (!ok) {
        std::printf("FAIL %s: got %.12g, want %.12g\n", what, got, want);
        ++failures;
    }
}

void closed_form(double a1, double a2, double off2, double q1, double q2, double p[2])
{
    p[0] = a1 * std::cos(q1) + a2 * std::cos(q1 + q2 + off2);
    p[1] = a1 * std::sin(q1) + a2 * std::sin(q1 + q2 + off2);
}

void planar_arm(dhc_arm *arm, double a1, double a2, double off2)
{
    (void)dhc_arm_init(arm, 2U);
    arm->joint[0].a_mm = a1;
    arm->joint[1].a_mm = a2;
    arm->joint[1].theta_offset_rad = off2;
}

// Angles from a fixed sequence: reproducible, spread over the circle.
double angle(unsigned k, unsigned j)
{
    return std::fmod(0.7 * k + 1.9 * j + 0.37 * k * j, 6.2) - 3.1;
}

constexpr unsigned kSamples = 24U;
dhc_sample samples[kSamples];
dhc_calib_workspace workspace;
dhc_calib_report report;

dhc_status read_sample(const void *, size_t index, dhc_sample *out)
{
    *out = samples[index];
    return DHC_OK;
}

} // namespace

int main()
{
#ifdef EXPECTED_VERSION
    check(std::strcmp(DHCAL_VERSION_STRING, EXPECTED_VERSION) == 0,
          "DHCAL_VERSION_STRING is the package's version", 0.0, 0.0);
#endif
    std::printf("dhcal %s (DHCAL_VERSION %d)\n", DHCAL_VERSION_STRING, DHCAL_VERSION);

    dhc_arm nominal;
    planar_arm(&nominal, kA1, kA2, 0.0);
    for (unsigned k = 0U; k < 8U; ++k) {
        double q[DHC_MAX_JOINTS] = {angle(k, 0U), angle(k, 1U)};
        dhc_frame tool;
        check(dhc_forward(&nominal, q, DHC_MAX_JOINTS, &tool) == DHC_OK, "dhc_forward", 0, 0);
        double want[2];
        closed_form(kA1, kA2, 0.0, q[0], q[1], want);
        check(std::fabs(tool.pos[0] - want[0]) < 1e-9, "forward x", tool.pos[0], want[0]);
        check(std::fabs(tool.pos[1] - want[1]) < 1e-9, "forward y", tool.pos[1], want[1]);
    }

    const double true_a1 = kA1 + 1.5;
    const double true_off2 = 0.01;
    for (unsigned k = 0U; k < kSamples; ++k) {
        dhc_sample &s = samples[k];
        std::memset(&s, 0, sizeof s);
        s.q_rad[0] = angle(k, 0U);
        s.q_rad[1] = angle(k, 1U);
        s.temp_c = 20.0;
        closed_form(true_a1, kA2, true_off2, s.q_rad[0], s.q_rad[1], s.p_mm);
        s.kind = DHC_MEAS_POSITION;
    }
    dhc_model model;
    check(dhc_model_init(&model, 2U) == DHC_OK, "dhc_model_init", 0, 0);
    planar_arm(&model.arm, kA1, kA2, 0.0);
    dhc_arm_choose_conventions(&model.arm, 1e-3);
    dhc_param_set set;
    check(dhc_params_base_model(&set, &model) == DHC_OK, "dhc_params_base_model", 0, 0);
    dhc_calib_options opt;
    dhc_calib_default_options(&opt);
    unsigned char flags[kSamples] = {};
    const dhc_status st = dhc_calib_fit(&model, &set, read_sample, nullptr, kSamples, flags, &opt,
                                        &workspace, &report);
    check(st == DHC_OK, "dhc_calib_fit status", st, DHC_OK);
    std::printf("fit: %s, %zu iterations, residual RMS %.3g mm\n", dhc_status_str(st),
                report.iterations, report.rms_mm);
    for (unsigned k = 0U; k < 8U; ++k) {
        const double q[DHC_MAX_JOINTS] = {angle(k + 100U, 0U), angle(k + 100U, 1U)};
        double got[3];
        check(dhc_model_tool_point(&model, q, nullptr, got) == DHC_OK, "tool point", 0, 0);
        double want[2];
        closed_form(true_a1, kA2, true_off2, q[0], q[1], want);
        check(std::hypot(got[0] - want[0], got[1] - want[1]) < 1e-6, "calibrated x", got[0],
              want[0]);
    }
    std::printf("%s\n", failures == 0 ? "consumer: all checks passed" : "consumer: FAILED");
    return failures == 0 ? 0 : 1;
}
