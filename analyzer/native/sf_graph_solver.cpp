// sf_graph_solver.cpp - the crowd graph solver on Ceres; the model is in sf_graph_solver.h.
#include "sf_graph_solver.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "sf_range_cost.h"  // the range row, shared with the coordinate solver (w = 1/sigma here)

namespace sf {
namespace {

// Step row: r = ((p_j - p_i) - s R(theta) d) / sigma; parameters p_i(2), p_j(2), theta_i(1), s_w(1).
// With u = R(theta) d: dr/dp_i = -I/sigma, dr/dp_j = +I/sigma, dr/dtheta = -s (-u_y, u_x)/sigma,
// dr/ds = -u/sigma.
class step_cost final : public ceres::SizedCostFunction<2, 2, 2, 1, 1> {
 public:
  step_cost(double dx_m, double dy_m, double sigma_m) : dx_m_(dx_m), dy_m_(dy_m), inv_(1.0 / sigma_m) {}
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const double* pi = parameters[0];
    const double* pj = parameters[1];
    const double th = parameters[2][0];
    const double s = parameters[3][0];
    const double c = std::cos(th);
    const double sn = std::sin(th);
    const double ux = c * dx_m_ - sn * dy_m_;
    const double uy = sn * dx_m_ + c * dy_m_;
    residuals[0] = ((pj[0] - pi[0]) - s * ux) * inv_;
    residuals[1] = ((pj[1] - pi[1]) - s * uy) * inv_;
    if (jacobians != nullptr) {
      if (jacobians[0] != nullptr) {  // 2x2 row-major
        jacobians[0][0] = -inv_; jacobians[0][1] = 0.0;
        jacobians[0][2] = 0.0;   jacobians[0][3] = -inv_;
      }
      if (jacobians[1] != nullptr) {
        jacobians[1][0] = inv_; jacobians[1][1] = 0.0;
        jacobians[1][2] = 0.0;  jacobians[1][3] = inv_;
      }
      if (jacobians[2] != nullptr) {
        jacobians[2][0] = s * uy * inv_;
        jacobians[2][1] = -s * ux * inv_;
      }
      if (jacobians[3] != nullptr) {
        jacobians[3][0] = -ux * inv_;
        jacobians[3][1] = -uy * inv_;
      }
    }
    return true;
  }

 private:
  const double dx_m_;
  const double dy_m_;
  const double inv_;
};

// Heading row: r = (theta_j - theta_i) / sigma; parameters theta_i, theta_j.
class heading_cost final : public ceres::SizedCostFunction<1, 1, 1> {
 public:
  explicit heading_cost(double sigma_rad) : inv_(1.0 / sigma_rad) {}
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    residuals[0] = (parameters[1][0] - parameters[0][0]) * inv_;
    if (jacobians != nullptr) {
      if (jacobians[0] != nullptr) jacobians[0][0] = -inv_;
      if (jacobians[1] != nullptr) jacobians[1][0] = inv_;
    }
    return true;
  }

 private:
  const double inv_;
};

// One-parameter prior: r = (v - v0) / sigma. The scale prior (parameter s_w) and the heading prior
// (parameter theta_k: the fleet's heading bias on a walk's first point) are both this row.
class prior_cost final : public ceres::SizedCostFunction<1, 1> {
 public:
  prior_cost(double prior, double sigma) : prior_(prior), inv_(1.0 / sigma) {}
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    residuals[0] = (parameters[0][0] - prior_) * inv_;
    if (jacobians != nullptr && jacobians[0] != nullptr) jacobians[0][0] = inv_;
    return true;
  }

 private:
  const double prior_;
  const double inv_;
};

// Anchor row: r = (p - q) / sigma (sf_coord_solver.cpp's anchor_cost with a weight 1/sigma).
class anchor_cost final : public ceres::SizedCostFunction<2, 2> {
 public:
  anchor_cost(double qx_m, double qy_m, double sigma_m) : qx_m_(qx_m), qy_m_(qy_m), inv_(1.0 / sigma_m) {}
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const double* p = parameters[0];
    residuals[0] = (p[0] - qx_m_) * inv_;
    residuals[1] = (p[1] - qy_m_) * inv_;
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      double* j = jacobians[0];
      j[0] = inv_; j[1] = 0.0;
      j[2] = 0.0;  j[3] = inv_;
    }
    return true;
  }

 private:
  const double qx_m_;
  const double qy_m_;
  const double inv_;
};

class checker {
 public:
  void add(const std::string& line) { problems_.push_back(line); }

  void size(const char* name, size_t got, size_t want, const char* of) {
    if (got != want) {
      add(std::string(name) + " has " + std::to_string(got) + " entries, expected " + std::to_string(want) +
          " (" + of + ")");
    }
  }

  void indices(const char* name, const std::vector<int64_t>& v, int64_t n, const char* what) {
    size_t bad = 0;
    size_t first = 0;
    for (size_t q = 0; q < v.size(); ++q) {
      if (v[q] < 0 || v[q] >= n) {
        if (bad++ == 0) first = q;
      }
    }
    if (bad > 0) {
      add(std::string(name) + ": " + std::to_string(bad) + " index(es) outside 0.." + std::to_string(n - 1) +
          " (" + what + "), first at row " + std::to_string(first) + " = " + std::to_string(v[first]));
    }
  }

  void distinct(const char* name, const std::vector<int64_t>& a, const std::vector<int64_t>& b) {
    size_t bad = 0;
    size_t first = 0;
    for (size_t q = 0; q < std::min(a.size(), b.size()); ++q) {
      if (a[q] == b[q]) {
        if (bad++ == 0) first = q;
      }
    }
    if (bad > 0) {
      add(std::string(name) + ": " + std::to_string(bad) + " row(s) join a point to itself (i == j), first at row " +
          std::to_string(first));
    }
  }

  void sigmas(const char* name, const std::vector<double>& v) {
    count_bad(name, v, [](double x) { return std::isfinite(x) && x > 0.0; }, "not > 0 and finite");
  }

  void finite(const char* name, const std::vector<double>& v) {
    count_bad(name, v, [](double x) { return std::isfinite(x); }, "non-finite");
  }

  void nonneg(const char* name, const std::vector<double>& v) {
    count_bad(name, v, [](double x) { return std::isfinite(x) && x >= 0.0; }, "negative or non-finite");
  }

  void throw_if_any() const {
    if (problems_.empty()) return;
    std::ostringstream os;
    os << "graph solver: " << problems_.size() << " problem(s) with the input:";
    for (const auto& p : problems_) os << "\n  - " << p;
    throw std::invalid_argument(os.str());
  }

 private:
  template <typename Ok>
  void count_bad(const char* name, const std::vector<double>& v, Ok ok, const char* what) {
    size_t bad = 0;
    size_t first = 0;
    for (size_t q = 0; q < v.size(); ++q) {
      if (!ok(v[q])) {
        if (bad++ == 0) first = q;
      }
    }
    if (bad > 0) {
      std::ostringstream os;
      os << name << ": " << bad << " value(s) " << what << ", first at entry " << first << " = " << v[first];
      add(os.str());
    }
  }

  std::vector<std::string> problems_;
};

}  // namespace

void sf_graph_validate(const graph_problem_t& g, const graph_options_t& opt) {
  checker c;
  const int64_t n = g.n_points;
  const int64_t W = g.n_walks;
  if (n < 1) c.add("n_points must be >= 1, got " + std::to_string(n));
  if (W < 0) c.add("n_walks must be >= 0, got " + std::to_string(W));
  const size_t nn = n > 0 ? static_cast<size_t>(n) : 0;
  const size_t ww = W > 0 ? static_cast<size_t>(W) : 0;

  const size_t k = g.step_i.size();
  c.size("step_j", g.step_j.size(), k, "one per step_i");
  c.size("step_walk", g.step_walk.size(), k, "one per step_i");
  c.size("step_dxy_m", g.step_dxy_m.size(), 2 * k, "2 per step_i");
  c.size("step_sigma_m", g.step_sigma_m.size(), k, "one per step_i");
  c.indices("step_i", g.step_i, n, "points");
  c.indices("step_j", g.step_j, n, "points");
  c.indices("step_walk", g.step_walk, W, "walks");
  c.distinct("steps", g.step_i, g.step_j);
  c.finite("step_dxy_m", g.step_dxy_m);
  c.sigmas("step_sigma_m", g.step_sigma_m);

  const size_t h = g.head_i.size();
  c.size("head_j", g.head_j.size(), h, "one per head_i");
  c.size("head_sigma_rad", g.head_sigma_rad.size(), h, "one per head_i");
  c.indices("head_i", g.head_i, n, "points");
  c.indices("head_j", g.head_j, n, "points");
  c.distinct("heading rows", g.head_i, g.head_j);
  c.sigmas("head_sigma_rad", g.head_sigma_rad);

  c.size("scale_prior", g.scale_prior.size(), ww, "one per walk");
  c.size("scale_sigma", g.scale_sigma.size(), ww, "one per walk");
  c.finite("scale_prior", g.scale_prior);
  c.sigmas("scale_sigma", g.scale_sigma);

  const size_t p = g.hprior_idx.size();
  c.size("hprior_rad", g.hprior_rad.size(), p, "one per hprior_idx");
  c.size("hprior_sigma_rad", g.hprior_sigma_rad.size(), p, "one per hprior_idx");
  c.indices("hprior_idx", g.hprior_idx, n, "points");
  c.finite("hprior_rad", g.hprior_rad);
  c.sigmas("hprior_sigma_rad", g.hprior_sigma_rad);

  const size_t a = g.anchor_idx.size();
  c.size("anchor_xy_m", g.anchor_xy_m.size(), 2 * a, "2 per anchor_idx");
  c.size("anchor_sigma_m", g.anchor_sigma_m.size(), a, "one per anchor_idx");
  c.indices("anchor_idx", g.anchor_idx, n, "points");
  c.finite("anchor_xy_m", g.anchor_xy_m);
  c.sigmas("anchor_sigma_m", g.anchor_sigma_m);

  const size_t r = g.pair_i.size();
  c.size("pair_j", g.pair_j.size(), r, "one per pair_i");
  c.size("range_m", g.range_m.size(), r, "one per pair_i");
  c.size("range_sigma_m", g.range_sigma_m.size(), r, "one per pair_i");
  c.indices("pair_i", g.pair_i, n, "points");
  c.indices("pair_j", g.pair_j, n, "points");
  c.distinct("pairs", g.pair_i, g.pair_j);
  c.nonneg("range_m", g.range_m);
  c.sigmas("range_sigma_m", g.range_sigma_m);

  if (g.loss != "none" && g.loss != "huber" && g.loss != "cauchy") {
    c.add("loss must be 'none', 'huber' or 'cauchy', got '" + g.loss + "'");
  }
  if (!(g.loss_scale > 0.0) || !std::isfinite(g.loss_scale)) c.add("loss_scale must be > 0 and finite");

  c.size("init_xy", g.init_xy_m.size(), 2 * nn, "2 per point");
  c.size("init_heading_rad", g.init_heading_rad.size(), nn, "one per point");
  c.size("init_scale", g.init_scale.size(), ww, "one per walk");
  c.finite("init_xy", g.init_xy_m);
  c.finite("init_heading_rad", g.init_heading_rad);
  c.finite("init_scale", g.init_scale);

  if (opt.max_iterations < 0) c.add("max_iterations must be >= 0");
  if (opt.num_threads < 1) c.add("num_threads must be >= 1");
  if (!(opt.function_tolerance >= 0.0) || !(opt.gradient_tolerance >= 0.0) || !(opt.parameter_tolerance >= 0.0)) {
    c.add("tolerances must be >= 0");
  }
  c.throw_if_any();
}

graph_result_t sf_graph_solve(const graph_problem_t& g, const graph_options_t& opt) {
  sf_graph_validate(g, opt);

  graph_result_t out;
  out.xy_m = g.init_xy_m;
  out.heading_rad = g.init_heading_rad;
  out.scale = g.init_scale;
  double* const xy = out.xy_m.data();
  double* const th = out.heading_rad.data();
  double* const sc = out.scale.data();

  // One loss for every range row: the problem must not own (and delete) it per row.
  std::unique_ptr<ceres::LossFunction> loss;
  if (g.loss == "huber") loss = std::make_unique<ceres::HuberLoss>(g.loss_scale);
  if (g.loss == "cauchy") loss = std::make_unique<ceres::CauchyLoss>(g.loss_scale);
  ceres::Problem::Options popt;
  popt.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(popt);
  for (int64_t i = 0; i < g.n_points; ++i) {
    problem.AddParameterBlock(xy + 2 * i, 2);
    problem.AddParameterBlock(th + i, 1);
  }
  for (int64_t w = 0; w < g.n_walks; ++w) problem.AddParameterBlock(sc + w, 1);

  for (size_t q = 0; q < g.step_i.size(); ++q) {
    const int64_t i = g.step_i[q];
    problem.AddResidualBlock(new step_cost(g.step_dxy_m[2 * q], g.step_dxy_m[2 * q + 1], g.step_sigma_m[q]),
                             nullptr, xy + 2 * i, xy + 2 * g.step_j[q], th + i, sc + g.step_walk[q]);
  }
  for (size_t q = 0; q < g.head_i.size(); ++q) {
    problem.AddResidualBlock(new heading_cost(g.head_sigma_rad[q]), nullptr, th + g.head_i[q], th + g.head_j[q]);
  }
  for (size_t w = 0; w < g.scale_prior.size(); ++w) {
    problem.AddResidualBlock(new prior_cost(g.scale_prior[w], g.scale_sigma[w]), nullptr, sc + w);
  }
  for (size_t q = 0; q < g.hprior_idx.size(); ++q) {
    problem.AddResidualBlock(new prior_cost(g.hprior_rad[q], g.hprior_sigma_rad[q]), nullptr, th + g.hprior_idx[q]);
  }
  for (size_t q = 0; q < g.anchor_idx.size(); ++q) {
    problem.AddResidualBlock(new anchor_cost(g.anchor_xy_m[2 * q], g.anchor_xy_m[2 * q + 1], g.anchor_sigma_m[q]),
                             nullptr, xy + 2 * g.anchor_idx[q]);
  }
  for (size_t q = 0; q < g.pair_i.size(); ++q) {
    problem.AddResidualBlock(new range_cost(g.range_m[q], 1.0 / g.range_sigma_m[q]), loss.get(), xy + 2 * g.pair_i[q],
                             xy + 2 * g.pair_j[q]);
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
  // Ceres reports -1 steps when it did not iterate at all (e.g. no residuals): that is 0 iterations.
  out.iterations = std::max(0, summary.num_successful_steps) + std::max(0, summary.num_unsuccessful_steps);
  out.converged = summary.termination_type == ceres::CONVERGENCE;
  out.time_s = summary.total_time_in_seconds;
  out.message = summary.message;
  if (summary.termination_type == ceres::FAILURE) {
    throw std::runtime_error("graph solver: Ceres failed: " + summary.message);
  }
  return out;
}

}  // namespace sf
