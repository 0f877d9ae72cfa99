// sf_coord_solver.cpp - the Kannan coordinate solver on Ceres; the model is in sf_coord_solver.h.
#include "sf_coord_solver.h"
#include "sf_range_cost.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace sf {
namespace {

// Anchor row: r = p - a (2 residuals, weight 1). Linear, so the Jacobian is the identity.
class anchor_cost final : public ceres::SizedCostFunction<2, 2> {
 public:
  anchor_cost(double ax_m, double ay_m) : ax_m_(ax_m), ay_m_(ay_m) {}
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const double* p = parameters[0];
    residuals[0] = p[0] - ax_m_;
    residuals[1] = p[1] - ay_m_;
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      double* j = jacobians[0];  // 2x2 row-major
      j[0] = 1.0; j[1] = 0.0;
      j[2] = 0.0; j[3] = 1.0;
    }
    return true;
  }

 private:
  const double ax_m_;
  const double ay_m_;
};

void throw_if_any(const std::vector<std::string>& problems) {
  if (problems.empty()) return;
  std::ostringstream os;
  os << "coordinate solver: " << problems.size() << " problem(s) with the input:";
  for (const auto& p : problems) os << "\n  - " << p;
  throw std::invalid_argument(os.str());
}

bool all_finite(const std::vector<double>& v) {
  return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
}

}  // namespace

std::vector<double> sf_coord_weights(const std::vector<double>& range_m, double m, double c_m) {
  std::vector<double> w(range_m.size());
  size_t bad = 0;
  for (size_t k = 0; k < range_m.size(); ++k) {
    const double denom = m * range_m[k] + c_m;
    w[k] = 1.0 / denom;
    if (!(denom > 0.0) || !std::isfinite(w[k])) ++bad;
  }
  if (bad > 0) {
    std::ostringstream os;
    os << "coordinate solver: weight law 1/(m*b + c) with m=" << m << ", c=" << c_m << " gives " << bad
       << " non-positive or non-finite weight(s); need c > -m*min(b)";
    throw std::invalid_argument(os.str());
  }
  return w;
}

std::vector<double> sf_coord_default_init(int64_t n_points, const std::vector<int64_t>& anchor_idx,
                                          const std::vector<double>& anchor_xy_m) {
  std::vector<std::string> problems;
  if (n_points < 1) problems.push_back("n_points must be >= 1");
  if (anchor_idx.empty()) problems.push_back("the default start needs at least one anchor (or pass init_xy)");
  if (anchor_xy_m.size() != 2 * anchor_idx.size()) problems.push_back("anchors_xy must be k x 2");
  for (const int64_t i : anchor_idx) {
    if (i < 0 || i >= n_points) {
      problems.push_back("anchor index " + std::to_string(i) + " outside 0.." + std::to_string(n_points - 1));
    }
  }
  throw_if_any(problems);

  const size_t n = static_cast<size_t>(n_points);
  std::vector<double> sum(2 * n, 0.0);
  std::vector<int> count(n, 0);
  for (size_t a = 0; a < anchor_idx.size(); ++a) {
    const size_t i = static_cast<size_t>(anchor_idx[a]);
    sum[2 * i] += anchor_xy_m[2 * a];
    sum[2 * i + 1] += anchor_xy_m[2 * a + 1];
    ++count[i];
  }
  std::vector<size_t> known;  // anchored points, ascending
  std::vector<double> xy(2 * n, 0.0);
  for (size_t i = 0; i < n; ++i) {
    if (count[i] > 0) {
      xy[2 * i] = sum[2 * i] / count[i];
      xy[2 * i + 1] = sum[2 * i + 1] / count[i];
      known.push_back(i);
    }
  }
  size_t next = 0;  // index into known of the first anchored point >= i
  for (size_t i = 0; i < n; ++i) {
    while (next < known.size() && known[next] < i) ++next;
    if (next < known.size() && known[next] == i) continue;
    size_t src_lo = 0;
    size_t src_hi = 0;
    double t = 0.0;
    if (next == 0) {
      src_lo = src_hi = known.front();  // before the first anchor: hold it
    } else if (next == known.size()) {
      src_lo = src_hi = known.back();  // past the last anchor: hold it
    } else {
      src_lo = known[next - 1];
      src_hi = known[next];
      t = static_cast<double>(i - src_lo) / static_cast<double>(src_hi - src_lo);
    }
    for (size_t d = 0; d < 2; ++d) {
      xy[2 * i + d] = (1.0 - t) * xy[2 * src_lo + d] + t * xy[2 * src_hi + d];
    }
  }
  return xy;
}

void sf_coord_validate(const coord_problem_t& pr, const std::vector<double>& init_xy_m) {
  std::vector<std::string> problems;
  const int64_t n = pr.n_points;
  if (n < 1) problems.push_back("n_points must be >= 1, got " + std::to_string(n));
  const size_t k = pr.anchor_idx.size();
  if (pr.anchor_xy_m.size() != 2 * k) {
    problems.push_back("anchors_xy has " + std::to_string(pr.anchor_xy_m.size() / 2) + " rows, anchors_idx " +
                       std::to_string(k));
  }
  size_t bad_anchor = 0;
  for (const int64_t i : pr.anchor_idx) bad_anchor += (i < 0 || i >= n) ? 1 : 0;
  if (bad_anchor > 0) problems.push_back(std::to_string(bad_anchor) + " anchor index(es) outside 0..n_points-1");
  if (!all_finite(pr.anchor_xy_m)) problems.push_back("anchors_xy has non-finite values");

  const size_t m = pr.range_m.size();
  if (pr.pair_idx.size() != 2 * m) {
    problems.push_back("pairs has " + std::to_string(pr.pair_idx.size() / 2) + " rows, ranges_m " +
                       std::to_string(m));
  }
  size_t bad_pair = 0;
  size_t self_pair = 0;
  for (size_t q = 0; q + 1 < pr.pair_idx.size(); q += 2) {
    const int64_t i = pr.pair_idx[q];
    const int64_t j = pr.pair_idx[q + 1];
    bad_pair += (i < 0 || i >= n || j < 0 || j >= n) ? 1 : 0;
    self_pair += (i == j) ? 1 : 0;
  }
  if (bad_pair > 0) problems.push_back(std::to_string(bad_pair) + " pair index(es) outside 0..n_points-1");
  if (self_pair > 0) problems.push_back(std::to_string(self_pair) + " pair(s) join a point to itself");
  size_t bad_range = 0;
  for (const double b : pr.range_m) bad_range += (std::isfinite(b) && b >= 0.0) ? size_t{0} : size_t{1};
  if (bad_range > 0) problems.push_back(std::to_string(bad_range) + " range(s) negative or non-finite");
  if (pr.weight_per_m.size() != m) {
    problems.push_back("weights has " + std::to_string(pr.weight_per_m.size()) + " entries, ranges_m " +
                       std::to_string(m));
  }
  size_t bad_weight = 0;
  for (const double w : pr.weight_per_m) bad_weight += (std::isfinite(w) && w > 0.0) ? size_t{0} : size_t{1};
  if (bad_weight > 0) problems.push_back(std::to_string(bad_weight) + " weight(s) non-positive or non-finite");

  if (!init_xy_m.empty()) {
    if (n >= 0 && init_xy_m.size() != 2 * static_cast<size_t>(n)) {
      problems.push_back("init_xy has " + std::to_string(init_xy_m.size() / 2) + " rows, n_points " +
                         std::to_string(n));
    }
    if (!all_finite(init_xy_m)) problems.push_back("init_xy has non-finite values");
  } else if (k == 0) {
    problems.push_back("no anchors and no init_xy: the default start needs at least one anchor");
  }
  throw_if_any(problems);
}

coord_result_t sf_coord_solve(const coord_problem_t& pr, const std::vector<double>& init_xy_m,
                              const coord_options_t& opt) {
  sf_coord_validate(pr, init_xy_m);
  {
    std::vector<std::string> problems;
    if (!(opt.loss_scale > 0.0) || !std::isfinite(opt.loss_scale)) problems.push_back("loss_scale must be > 0");
    if (opt.max_iterations < 0) problems.push_back("max_iterations must be >= 0");
    if (opt.num_threads < 1) problems.push_back("num_threads must be >= 1");
    if (!(opt.function_tolerance >= 0.0) || !(opt.gradient_tolerance >= 0.0) || !(opt.parameter_tolerance >= 0.0)) {
      problems.push_back("tolerances must be >= 0");
    }
    throw_if_any(problems);
  }

  coord_result_t out;
  out.xy_m = init_xy_m.empty() ? sf_coord_default_init(pr.n_points, pr.anchor_idx, pr.anchor_xy_m) : init_xy_m;
  double* const xy = out.xy_m.data();

  // The loss is shared by every range row, so the problem must not own (and delete) it per row.
  std::unique_ptr<ceres::LossFunction> loss;
  switch (opt.loss) {
    case robust_loss::none: break;
    case robust_loss::huber: loss = std::make_unique<ceres::HuberLoss>(opt.loss_scale); break;
    case robust_loss::cauchy: loss = std::make_unique<ceres::CauchyLoss>(opt.loss_scale); break;
  }
  ceres::Problem::Options popt;
  popt.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(popt);
  for (int64_t i = 0; i < pr.n_points; ++i) problem.AddParameterBlock(xy + 2 * i, 2);
  for (size_t a = 0; a < pr.anchor_idx.size(); ++a) {
    problem.AddResidualBlock(new anchor_cost(pr.anchor_xy_m[2 * a], pr.anchor_xy_m[2 * a + 1]), nullptr,
                             xy + 2 * pr.anchor_idx[a]);
  }
  for (size_t k = 0; k < pr.range_m.size(); ++k) {
    problem.AddResidualBlock(new range_cost(pr.range_m[k], pr.weight_per_m[k]), loss.get(),
                             xy + 2 * pr.pair_idx[2 * k], xy + 2 * pr.pair_idx[2 * k + 1]);
  }

  ceres::Solver::Options so;
  so.minimizer_type = ceres::TRUST_REGION;
  so.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  so.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  if (!ceres::IsSparseLinearAlgebraLibraryTypeAvailable(so.sparse_linear_algebra_library_type)) {
    so.linear_solver_type = ceres::DENSE_QR;  // DEVIATION: a Ceres without sparse support; fine for small n
  }
  so.max_num_iterations = opt.max_iterations;
  so.function_tolerance = opt.function_tolerance;
  so.gradient_tolerance = opt.gradient_tolerance;
  so.parameter_tolerance = opt.parameter_tolerance;
  so.num_threads = opt.num_threads;
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;

  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  out.cost = summary.final_cost;
  out.initial_cost = summary.initial_cost;
  out.iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
  out.converged = summary.termination_type == ceres::CONVERGENCE;
  out.time_s = summary.total_time_in_seconds;
  out.message = summary.message;
  if (opt.full_report) out.report = summary.FullReport();
  if (summary.termination_type == ceres::FAILURE) {
    throw std::runtime_error("coordinate solver: Ceres failed: " + summary.message);
  }
  return out;
}

}  // namespace sf
