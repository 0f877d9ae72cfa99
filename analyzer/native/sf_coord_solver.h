// sf_coord_solver.h - the Kannan (2024) coordinate solver: 2-D positions of a walk's points from a few
// anchors and many pairwise ranges, by weighted nonlinear least squares (Ceres).
//
// Model (thesis §4, Eqs. 6-10 and 18-19; /work/shared/papers/kannan-2024-crowdsourced-wifi.md):
//   unknowns  p_i = (x_i, y_i) in metres, i = 0..n-1 (a local east/north frame, any origin);
//   anchor rows   r = p_i - a_i                           2 residuals per anchor, weight 1
//                 (BLE beacons, GPS fixes, landmarks; the thesis simulates every 4th point);
//   range rows    r = w_k * (b_k - |p_I - p_J|)            1 residual per pair k = (I, J)
//                 b_k = observed distance in metres (PDR pairwise distance or Wi-Fi model distance),
//                 w_k = 1 / (m * b_k + c) in 1/m: the thesis's inverse-linear law, optimum m = 1,
//                 c = 2 m (the listing's `inv(diag(slope*b2 + intercept))`); or an explicit w_k.
//   cost      = 1/2 * sum over anchor rows |r|^2 + 1/2 * sum over range rows rho(r^2)
//   rho       = identity ("none"), or Ceres's HuberLoss / CauchyLoss with scale loss_scale on the range
//               rows only: anchors are "100 % confidence" in the thesis and are never down-weighted.
// The reliability filter (tau) chooses which pairs enter; it is the caller's job (Python side).
//
// |p_I - p_J| = 0: the residual is defined (w * b) but the norm has no derivative there. Below
// SF_COORD_MIN_DIST_M the Jacobian takes the unit direction of p_J - p_I as +x (east): a subgradient (any
// unit vector is one), chosen so that coincident starting points are pushed apart instead of stuck, and a
// walk started on one point (e.g. the constant default start past the last anchor, pairs given as
// (earlier, later)) unfolds eastwards in index order. The distance itself is never biased, so the thesis's
// 1-D check (positions 1..5, first known, unit ranges) comes back exact, even from the default start.
//
// Default initialisation (when no start is given; thesis §4 "x0 = b1, the rest from a linear guess"):
// anchors at their positions (the mean if a point has several), each free point linearly interpolated in
// index order between the nearest anchored points before and after it (the thesis's points are a walk,
// a sequence), and held constant at the first/last anchor beyond the ends. At least one anchor is needed.
//
// Cost per solve: one sparse Levenberg-Marquardt (SPARSE_NORMAL_CHOLESKY, SuiteSparse) over 2n unknowns;
// each iteration is O(rows) to evaluate plus a sparse Cholesky whose fill depends on the pair graph
// (a band for consecutive pairs). Memory O(n + rows). No globals; thread-safe for distinct inputs.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace sf {

constexpr double SF_COORD_MIN_DIST_M = 1e-12;  // below this |p_I - p_J|, p_J - p_I is taken as +x

enum class robust_loss { none, huber, cauchy };

struct coord_problem_t {
  int64_t n_points = 0;
  std::vector<int64_t> anchor_idx;    // k indices into 0..n-1
  std::vector<double> anchor_xy_m;    // k*2, row-major (x, y)
  std::vector<int64_t> pair_idx;      // m*2, row-major (I, J), I != J
  std::vector<double> range_m;        // m observed distances b_k >= 0
  std::vector<double> weight_per_m;   // m explicit weights w_k > 0 (already 1/(m*b + c) or any law)
};

struct coord_options_t {
  robust_loss loss = robust_loss::none;
  double loss_scale = 1.0;            // in residual units (w * metres), > 0
  int max_iterations = 200;
  double function_tolerance = 1e-10;  // Ceres: |d cost| / cost
  double gradient_tolerance = 1e-12;  // Ceres: max-norm of the gradient
  double parameter_tolerance = 1e-10; // Ceres: |dx| / (|x| + tol)
  int num_threads = 1;
  bool full_report = false;           // fill coord_result_t::report (timings per stage, linear solver)
};

struct coord_result_t {
  std::vector<double> xy_m;           // n*2 row-major
  double cost = 0.0;                  // final Ceres cost (1/2 sum rho), as defined above
  double initial_cost = 0.0;
  int iterations = 0;                 // Ceres iterations (the summary's iteration records minus the 0th)
  bool converged = false;             // terminated by a tolerance (Ceres CONVERGENCE)
  double time_s = 0.0;                // Ceres total wall time
  std::string message;                // Ceres termination message
  std::string report;                 // Ceres FullReport() when coord_options_t::full_report
};

// Weights of the thesis's law, w_k = 1 / (m * b_k + c). Throws std::invalid_argument when any weight
// would be non-positive or non-finite (that is, unless c > -m * min(b)).
std::vector<double> sf_coord_weights(const std::vector<double>& range_m, double m, double c_m);

// The default start described above. Throws std::invalid_argument on bad input or no anchors.
std::vector<double> sf_coord_default_init(int64_t n_points, const std::vector<int64_t>& anchor_idx,
                                          const std::vector<double>& anchor_xy_m);

// Checks every input and throws std::invalid_argument listing all the problems found.
void sf_coord_validate(const coord_problem_t& problem, const std::vector<double>& init_xy_m);

// Solves from init_xy_m (n*2; empty = the default start). Throws std::invalid_argument on bad input.
coord_result_t sf_coord_solve(const coord_problem_t& problem, const std::vector<double>& init_xy_m,
                              const coord_options_t& options);

}  // namespace sf
