// ceres_fit: the Ceres peer of bench/run. Fits the link geometry of a serial arm to measured
// tool points with Ceres, on the files `dhcal fit` reads, so that both solve one problem.
//
//   ceres_fit --model M.json --data D.csv [--solver solve|solve-qr|tiny] [--one-block]
//
// The problem is dhcal's default geometric fit (docs/formats.md): the chain
// p = base * A_1 * ... * A_N * tool_mm with A_i = Rz(q_i + theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)
// Ry(beta_i); per joint theta, a, alpha and d, except that a joint other than the last whose
// nominal twist is parallel (|sin alpha| < 1e-3) fits beta in place of d (Hayati). alpha of
// the last joint is left out when the tool point lies on its x axis (it cannot move the
// point). Base and tool stay as the model gives them. Residuals are the three components of
// (predicted - measured) per row, so RMS = sqrt(sum |e|^2 / rows), dhcal's rms_mm.
//
// The Jacobian is analytic (the derivative of the tool point is a screw about the joint
// axis concerned), written once in point_and_jacobian() and used by both solvers:
//   solve     ceres::Solve, Levenberg-Marquardt, DENSE_NORMAL_CHOLESKY, one thread, one
//             residual block of three residuals per row (the usual Ceres layout);
//   solve-qr  the same with DENSE_QR;
//   tiny      ceres::TinySolver (dense LM on the normal equations, Eigen LDLT), all rows in
//             one functor.
// --one-block gives ceres::Solve all rows as one residual block instead; it is slower here
// (2000 rows: 11.3 ms against 8.3 ms for the solver call), so bench/run does not use it.
// Dense linear algebra stays Eigen's: LAPACK measured no faster at this size.
// Prints one JSON object: the solver, the parameter names (dhcal's naming, so bench/run can
// check that both fit the same set), rows, iterations, rms_mm, solve_ms (the solver call) and
// process_ms (from the start of main: parsing the files, setting up, solving).
// Exit status: 0 on success, 1 when the solver fails, 2 for bad usage or input.

#include <ceres/ceres.h>
#include <ceres/tiny_solver.h>
#include <cjson/cJSON.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace
{

using Clock = std::chrono::steady_clock;
constexpr double kDeg = M_PI / 180.0;
constexpr int kMaxJoints = 16;

double ms_since(Clock::time_point t0)
{
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

[[noreturn]] void die(const std::string &msg)
{
    std::fprintf(stderr, "ceres_fit: %s\n", msg.c_str());
    std::exit(2);
}

struct Joint {
    double theta = 0.0, d = 0.0, a = 0.0, alpha = 0.0, beta = 0.0; // rad, mm
};

struct Model {
    std::vector<Joint> joints;
    double base_r[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}; // row-major
    double base_p[3] = {0, 0, 0};
    double tool[3] = {0, 0, 0};
};

enum class Kind { theta, d, a, alpha, beta };

struct Param {
    int joint; // 0-based
    Kind kind;
};

std::string param_name(const Param &p)
{
    static const char *const names[] = {"theta", "d", "a", "alpha", "beta"};
    return names[static_cast<int>(p.kind)] + std::to_string(p.joint + 1);
}

// ---------------------------------------------------------------- files

std::string read_file(const char *path)
{
    std::ifstream f(path, std::ios::binary);
    if (!f)
        die(std::string(path) + ": cannot open");
    std::ostringstream s;
    s << f.rdbuf();
    return s.str();
}

double json_number(const cJSON *obj, const char *key, double fallback, const char *where)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (v == nullptr)
        return fallback;
    if (!cJSON_IsNumber(v))
        die(std::string(where) + "." + key + ": expected a number");
    return v->valuedouble;
}

void json_vec3(const cJSON *obj, const char *key, double out[3], const char *where)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (v == nullptr)
        return;
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 3)
        die(std::string(where) + "." + key + ": expected [x, y, z]");
    for (int k = 0; k < 3; ++k) {
        const cJSON *e = cJSON_GetArrayItem(v, k);
        if (!cJSON_IsNumber(e))
            die(std::string(where) + "." + key + ": expected numbers");
        out[k] = e->valuedouble;
    }
}

// The subset of the model file (docs/formats.md section 2) that a geometric fit uses. Keys
// that change the prediction beyond that (effects, a measurer) are refused, not ignored.
Model load_model(const char *path)
{
    const std::string text = read_file(path);
    cJSON *root = cJSON_Parse(text.c_str());
    if (root == nullptr || !cJSON_IsObject(root))
        die(std::string(path) + ": not a JSON object");
    Model m;
    const cJSON *item = nullptr;
    cJSON_ArrayForEach(item, root)
    {
        const std::string key = item->string;
        if (key != "name" && key != "joints" && key != "tool_mm" && key != "base" &&
            key != "gravity")
            die(std::string(path) + ": key '" + key + "' is not supported by the Ceres peer");
    }
    const cJSON *joints = cJSON_GetObjectItemCaseSensitive(root, "joints");
    if (!cJSON_IsArray(joints) || cJSON_GetArraySize(joints) < 1 ||
        cJSON_GetArraySize(joints) > kMaxJoints)
        die(std::string(path) + ": joints: expected an array of 1 to 16 joints");
    const cJSON *j = nullptr;
    cJSON_ArrayForEach(j, joints)
    {
        Joint jt;
        jt.theta = json_number(j, "theta_offset_deg", 0.0, "joints[]") * kDeg;
        jt.d = json_number(j, "d_mm", 0.0, "joints[]");
        jt.a = json_number(j, "a_mm", 0.0, "joints[]");
        jt.alpha = json_number(j, "alpha_deg", 0.0, "joints[]") * kDeg;
        jt.beta = json_number(j, "beta_deg", 0.0, "joints[]") * kDeg;
        m.joints.push_back(jt);
    }
    json_vec3(root, "tool_mm", m.tool, "model");
    const cJSON *base = cJSON_GetObjectItemCaseSensitive(root, "base");
    if (base != nullptr) {
        double rpy[3] = {0, 0, 0};
        json_vec3(base, "xyz_mm", m.base_p, "base");
        json_vec3(base, "rpy_deg", rpy, "base");
        // R = Rz(yaw) Ry(pitch) Rx(roll)
        const double cr = std::cos(rpy[0] * kDeg), sr = std::sin(rpy[0] * kDeg);
        const double cp = std::cos(rpy[1] * kDeg), sp = std::sin(rpy[1] * kDeg);
        const double cy = std::cos(rpy[2] * kDeg), sy = std::sin(rpy[2] * kDeg);
        const double r[9] = {cy * cp,
                             cy * sp * sr - sy * cr,
                             cy * sp * cr + sy * sr,
                             sy * cp,
                             sy * sp * sr + cy * cr,
                             sy * sp * cr - cy * sr,
                             -sp,
                             cp * sr,
                             cp * cr};
        std::memcpy(m.base_r, r, sizeof r);
    }
    cJSON_Delete(root);
    return m;
}

struct Data {
    int rows = 0;
    std::vector<double> q;    // rows x N, rad
    std::vector<double> meas; // rows x 3, mm
};

std::string trim(const std::string &s)
{
    const size_t b = s.find_first_not_of(" \t\r");
    const size_t e = s.find_last_not_of(" \t\r");
    return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

// Measurement CSV (docs/formats.md section 3): '#' comments, a header naming q1..qN and
// x,y,z; other columns are refused, since dhcal would use them.
Data load_data(const char *path, int n_joints)
{
    const std::string text = read_file(path);
    Data data;
    std::vector<int> col_of; // column -> slot: 0..N-1 joints, N..N+2 x,y,z
    size_t pos = 0;
    int line_no = 0;
    bool header = false;
    std::vector<double> fields;
    while (pos < text.size()) {
        size_t end = text.find('\n', pos);
        if (end == std::string::npos)
            end = text.size();
        const std::string line = trim(text.substr(pos, end - pos));
        pos = end + 1;
        ++line_no;
        if (line.empty() || line[0] == '#')
            continue;
        if (!header) {
            std::stringstream ss(line);
            std::string name;
            int seen = 0;
            while (std::getline(ss, name, ',')) {
                name = trim(name);
                int slot = -1;
                if (name == "x" || name == "y" || name == "z")
                    slot = n_joints + (name[0] - 'x');
                else if (name.size() >= 2 && name[0] == 'q') {
                    const int k = std::atoi(name.c_str() + 1);
                    if (k >= 1 && k <= n_joints && name == "q" + std::to_string(k))
                        slot = k - 1;
                }
                if (slot < 0)
                    die(std::string(path) + ": column '" + name +
                        "' is not supported by the Ceres peer");
                col_of.push_back(slot);
                seen |= 1 << slot;
            }
            if (seen != (1 << (n_joints + 3)) - 1)
                die(std::string(path) + ": the header needs q1..qN and x,y,z");
            header = true;
            fields.resize(static_cast<size_t>(n_joints) + 3);
            continue;
        }
        const char *c = line.c_str();
        for (size_t k = 0; k < col_of.size(); ++k) {
            char *after = nullptr;
            const double v = std::strtod(c, &after);
            if (after == c || !std::isfinite(v))
                die(std::string(path) + ":" + std::to_string(line_no) + ": not a number");
            fields[static_cast<size_t>(col_of[k])] = v;
            while (*after == ' ' || *after == '\t')
                ++after;
            if (k + 1 < col_of.size() && *after++ != ',')
                die(std::string(path) + ":" + std::to_string(line_no) + ": too few fields");
            c = after;
        }
        if (*c != '\0')
            die(std::string(path) + ":" + std::to_string(line_no) + ": too many fields");
        for (int i = 0; i < n_joints; ++i)
            data.q.push_back(fields[static_cast<size_t>(i)] * kDeg);
        for (int k = 0; k < 3; ++k)
            data.meas.push_back(fields[static_cast<size_t>(n_joints + k)]);
        ++data.rows;
    }
    if (data.rows == 0)
        die(std::string(path) + ": no data rows");
    return data;
}

// ---------------------------------------------------------------- the problem

std::vector<Param> default_params(const Model &m)
{
    std::vector<Param> ps;
    const int n = static_cast<int>(m.joints.size());
    for (int i = 0; i < n; ++i) {
        const bool last = i == n - 1;
        const bool hayati = !last && std::fabs(std::sin(m.joints[i].alpha)) < 1e-3;
        ps.push_back({i, Kind::theta});
        ps.push_back({i, hayati ? Kind::beta : Kind::d});
        ps.push_back({i, Kind::a});
        // alpha of the last joint turns the tool point about its own x axis: no effect when
        // the point lies on that axis.
        if (!last || std::fabs(m.tool[1]) > 0.0 || std::fabs(m.tool[2]) > 0.0)
            ps.push_back({i, Kind::alpha});
    }
    return ps;
}

// The arm the parameters x (deltas from nominal, rad and mm) describe.
void apply(const Model &nominal, const std::vector<Param> &ps, const double *x, Joint *out)
{
    const size_t n = nominal.joints.size();
    for (size_t i = 0; i < n; ++i)
        out[i] = nominal.joints[i];
    for (size_t k = 0; k < ps.size(); ++k) {
        Joint &j = out[ps[k].joint];
        switch (ps[k].kind) {
        case Kind::theta: j.theta += x[k]; break;
        case Kind::d: j.d += x[k]; break;
        case Kind::a: j.a += x[k]; break;
        case Kind::alpha: j.alpha += x[k]; break;
        case Kind::beta: j.beta += x[k]; break;
        }
    }
}

inline void cross(const double u[3], const double v[3], double out[3])
{
    out[0] = u[1] * v[2] - u[2] * v[1];
    out[1] = u[2] * v[0] - u[0] * v[2];
    out[2] = u[0] * v[1] - u[1] * v[0];
}

// Tool point of one row, and when jac is not null its derivative with respect to the
// parameters: d p / d x_k goes to jac[c * row_stride + k * col_stride], c = 0..2.
// Columns of the frame are tracked in the world: before joint i the frame is (R, o); the
// joint turns it about z = R e_z through o (theta), moves it along z (d), along the turned x
// axis x1 (a), turns it about x1 (alpha) and then about the new y axis y2 (beta), both
// through the new origin o_i. Each derivative is that motion applied to the tool point.
void point_and_jacobian(const Model &nominal, const Joint *arm, const std::vector<Param> &ps,
                        const double *q, double p[3], double *jac, int row_stride, int col_stride)
{
    const int n = static_cast<int>(nominal.joints.size());
    double X[3], Y[3], Z[3], o[3];
    for (int r = 0; r < 3; ++r) {
        X[r] = nominal.base_r[3 * r + 0];
        Y[r] = nominal.base_r[3 * r + 1];
        Z[r] = nominal.base_r[3 * r + 2];
        o[r] = nominal.base_p[r];
    }
    double z_prev[kMaxJoints][3], o_prev[kMaxJoints][3], x1s[kMaxJoints][3], y2s[kMaxJoints][3],
        o_new[kMaxJoints][3];
    for (int i = 0; i < n; ++i) {
        const Joint &j = arm[i];
        const double phi = q[i] + j.theta;
        const double c = std::cos(phi), s = std::sin(phi);
        const double ca = std::cos(j.alpha), sa = std::sin(j.alpha);
        const double cb = std::cos(j.beta), sb = std::sin(j.beta);
        double x1[3], y1[3], y2[3], z2[3];
        for (int r = 0; r < 3; ++r) {
            z_prev[i][r] = Z[r];
            o_prev[i][r] = o[r];
            x1[r] = c * X[r] + s * Y[r];
            y1[r] = -s * X[r] + c * Y[r];
            o[r] += j.d * Z[r] + j.a * x1[r];
        }
        for (int r = 0; r < 3; ++r) {
            y2[r] = ca * y1[r] + sa * Z[r];
            z2[r] = -sa * y1[r] + ca * Z[r];
        }
        for (int r = 0; r < 3; ++r) {
            X[r] = cb * x1[r] - sb * z2[r];
            Y[r] = y2[r];
            Z[r] = sb * x1[r] + cb * z2[r];
            x1s[i][r] = x1[r];
            y2s[i][r] = y2[r];
            o_new[i][r] = o[r];
        }
    }
    for (int r = 0; r < 3; ++r)
        p[r] = o[r] + X[r] * nominal.tool[0] + Y[r] * nominal.tool[1] + Z[r] * nominal.tool[2];
    if (jac == nullptr)
        return;
    for (size_t k = 0; k < ps.size(); ++k) {
        const int i = ps[k].joint;
        double col[3] = {0.0, 0.0, 0.0}, arm_vec[3];
        switch (ps[k].kind) {
        case Kind::theta:
            for (int r = 0; r < 3; ++r)
                arm_vec[r] = p[r] - o_prev[i][r];
            cross(z_prev[i], arm_vec, col);
            break;
        case Kind::d:
            for (int r = 0; r < 3; ++r)
                col[r] = z_prev[i][r];
            break;
        case Kind::a:
            for (int r = 0; r < 3; ++r)
                col[r] = x1s[i][r];
            break;
        case Kind::alpha:
            for (int r = 0; r < 3; ++r)
                arm_vec[r] = p[r] - o_new[i][r];
            cross(x1s[i], arm_vec, col);
            break;
        case Kind::beta:
            for (int r = 0; r < 3; ++r)
                arm_vec[r] = p[r] - o_new[i][r];
            cross(y2s[i], arm_vec, col);
            break;
        }
        for (int r = 0; r < 3; ++r)
            jac[r * row_stride + static_cast<int>(k) * col_stride] = col[r];
    }
}

struct Problem {
    Model model;
    Data data;
    std::vector<Param> params;
};

// One row for ceres::Solve: three residuals, one parameter block of all parameters.
class RowCost final : public ceres::CostFunction
{
  public:
    RowCost(const Problem &pb, int row) : pb_(pb), row_(row)
    {
        set_num_residuals(3);
        mutable_parameter_block_sizes()->push_back(static_cast<int>(pb.params.size()));
    }

    bool Evaluate(double const *const *x, double *residuals, double **jacobians) const override
    {
        Joint arm[kMaxJoints];
        apply(pb_.model, pb_.params, x[0], arm);
        const size_t n = pb_.model.joints.size();
        double *jac = jacobians != nullptr ? jacobians[0] : nullptr;
        double p[3];
        point_and_jacobian(pb_.model, arm, pb_.params, &pb_.data.q[row_ * n], p, jac,
                           static_cast<int>(pb_.params.size()), 1);
        for (int r = 0; r < 3; ++r)
            residuals[r] = p[r] - pb_.data.meas[3 * static_cast<size_t>(row_) + r];
        return true;
    }

  private:
    const Problem &pb_;
    int row_;
};

// All rows in one residual block (--one-block): fewer, larger blocks for ceres::Solve.
class AllRowsCost final : public ceres::CostFunction
{
  public:
    explicit AllRowsCost(const Problem &pb) : pb_(pb)
    {
        set_num_residuals(3 * pb.data.rows);
        mutable_parameter_block_sizes()->push_back(static_cast<int>(pb.params.size()));
    }

    bool Evaluate(double const *const *x, double *residuals, double **jacobians) const override
    {
        Joint arm[kMaxJoints];
        apply(pb_.model, pb_.params, x[0], arm);
        const size_t n = pb_.model.joints.size();
        const int np = static_cast<int>(pb_.params.size());
        double *jac = jacobians != nullptr ? jacobians[0] : nullptr;
        for (int row = 0; row < pb_.data.rows; ++row) {
            double p[3];
            point_and_jacobian(pb_.model, arm, pb_.params, &pb_.data.q[row * n], p,
                               jac != nullptr ? jac + 3 * row * np : nullptr, np, 1);
            for (int r = 0; r < 3; ++r)
                residuals[3 * row + r] = p[r] - pb_.data.meas[3 * static_cast<size_t>(row) + r];
        }
        return true;
    }

  private:
    const Problem &pb_;
};

// All rows for TinySolver; its Jacobian is column-major, rows x parameters.
struct TinyFunctor {
    typedef double Scalar;
    enum { NUM_RESIDUALS = Eigen::Dynamic, NUM_PARAMETERS = Eigen::Dynamic };
    const Problem &pb;

    int NumResiduals() const
    {
        return 3 * pb.data.rows;
    }
    int NumParameters() const
    {
        return static_cast<int>(pb.params.size());
    }

    bool operator()(const double *x, double *residuals, double *jacobian) const
    {
        Joint arm[kMaxJoints];
        apply(pb.model, pb.params, x, arm);
        const size_t n = pb.model.joints.size();
        const int m = NumResiduals();
        for (int row = 0; row < pb.data.rows; ++row) {
            double p[3];
            double *jac = jacobian != nullptr ? jacobian + 3 * row : nullptr;
            point_and_jacobian(pb.model, arm, pb.params, &pb.data.q[row * n], p, jac, 1, m);
            for (int r = 0; r < 3; ++r)
                residuals[3 * row + r] = p[r] - pb.data.meas[3 * static_cast<size_t>(row) + r];
        }
        return true;
    }
};

double rms_of(const Problem &pb, const double *x)
{
    Joint arm[kMaxJoints];
    apply(pb.model, pb.params, x, arm);
    const size_t n = pb.model.joints.size();
    double ss = 0.0;
    for (int row = 0; row < pb.data.rows; ++row) {
        double p[3];
        point_and_jacobian(pb.model, arm, pb.params, &pb.data.q[row * n], p, nullptr, 0, 0);
        for (int r = 0; r < 3; ++r) {
            const double e = p[r] - pb.data.meas[3 * static_cast<size_t>(row) + r];
            ss += e * e;
        }
    }
    return std::sqrt(ss / pb.data.rows);
}

const char *tiny_status(int s)
{
    using T = ceres::TinySolver<TinyFunctor>;
    switch (s) {
    case T::GRADIENT_TOO_SMALL: return "gradient_too_small";
    case T::RELATIVE_STEP_SIZE_TOO_SMALL: return "relative_step_size_too_small";
    case T::COST_TOO_SMALL: return "cost_too_small";
    case T::HIT_MAX_ITERATIONS: return "hit_max_iterations";
    case T::COST_CHANGE_TOO_SMALL: return "cost_change_too_small";
    default: return "unknown";
    }
}

} // namespace

int main(int argc, char **argv)
{
    const Clock::time_point t_start = Clock::now();
    const char *model_path = nullptr, *data_path = nullptr;
    std::string solver = "solve";
    bool one_block = false;
    for (int k = 1; k < argc; ++k) {
        const std::string a = argv[k];
        if (k + 1 < argc && a == "--model")
            model_path = argv[++k];
        else if (k + 1 < argc && a == "--data")
            data_path = argv[++k];
        else if (a == "--one-block")
            one_block = true;
        else if (k + 1 < argc && a == "--solver")
            solver = argv[++k];
        else
            die("usage: ceres_fit --model M.json --data D.csv [--solver solve|solve-qr|tiny] "
                "[--one-block]");
    }
    if (model_path == nullptr || data_path == nullptr ||
        (solver != "solve" && solver != "solve-qr" && solver != "tiny"))
        die("usage: ceres_fit --model M.json --data D.csv [--solver solve|solve-qr|tiny] "
            "[--one-block]");

    Problem pb;
    pb.model = load_model(model_path);
    pb.data = load_data(data_path, static_cast<int>(pb.model.joints.size()));
    pb.params = default_params(pb.model);
    const int np = static_cast<int>(pb.params.size());
    if (3 * pb.data.rows < np)
        die("fewer residuals than parameters");

    std::vector<double> x(static_cast<size_t>(np), 0.0);
    int iterations = 0;
    bool ok = false;
    std::string termination;
    double solve_ms = 0.0;
    if (solver == "tiny") {
        TinyFunctor f{pb};
        ceres::TinySolver<TinyFunctor> tiny;
        Eigen::VectorXd xv = Eigen::VectorXd::Zero(np);
        const Clock::time_point t0 = Clock::now();
        const auto &summary = tiny.Solve(f, &xv);
        solve_ms = ms_since(t0);
        for (int k = 0; k < np; ++k)
            x[static_cast<size_t>(k)] = xv[k];
        iterations = summary.iterations;
        termination = tiny_status(summary.status);
        ok = summary.status != ceres::TinySolver<TinyFunctor>::HIT_MAX_ITERATIONS;
    } else {
        ceres::Problem problem;
        if (one_block)
            problem.AddResidualBlock(new AllRowsCost(pb), nullptr, x.data());
        else
            for (int row = 0; row < pb.data.rows; ++row)
                problem.AddResidualBlock(new RowCost(pb, row), nullptr, x.data());
        ceres::Solver::Options options;
        options.minimizer_type = ceres::TRUST_REGION;
        options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
        options.linear_solver_type =
            solver == "solve" ? ceres::DENSE_NORMAL_CHOLESKY : ceres::DENSE_QR;
        options.num_threads = 1;
        options.logging_type = ceres::SILENT;
        options.minimizer_progress_to_stdout = false;
        ceres::Solver::Summary summary;
        const Clock::time_point t0 = Clock::now();
        ceres::Solve(options, &problem, &summary);
        solve_ms = ms_since(t0);
        // Iterations as Ceres counts them in its report: accepted and rejected steps, not
        // the evaluation at the start.
        iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
        termination = ceres::TerminationTypeToString(summary.termination_type);
        ok = summary.IsSolutionUsable();
    }
    const double rms = rms_of(pb, x.data());
    const double process_ms = ms_since(t_start);

    Joint arm[kMaxJoints];
    apply(pb.model, pb.params, x.data(), arm);
    std::printf("{\"solver\": \"%s\", \"rows\": %d, \"iterations\": %d, \"termination\": \"%s\", "
                "\"rms_mm\": %.17g, \"solve_ms\": %.4f, \"process_ms\": %.4f, \"parameters\": [",
                solver.c_str(), pb.data.rows, iterations, termination.c_str(), rms, solve_ms,
                process_ms);
    for (int k = 0; k < np; ++k) {
        const Param &p = pb.params[static_cast<size_t>(k)];
        const Joint &j = arm[p.joint];
        double v = 0.0;
        switch (p.kind) {
        case Kind::theta: v = j.theta / kDeg; break;
        case Kind::d: v = j.d; break;
        case Kind::a: v = j.a; break;
        case Kind::alpha: v = j.alpha / kDeg; break;
        case Kind::beta: v = j.beta / kDeg; break;
        }
        std::printf("%s{\"name\": \"%s\", \"value\": %.17g}", k > 0 ? ", " : "",
                    param_name(p).c_str(), v);
    }
    std::printf("]}\n");
    return ok ? 0 : 1;
}
