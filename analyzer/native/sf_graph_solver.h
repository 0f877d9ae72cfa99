// sf_graph_solver.h - the crowd graph solver: every constraint a crowd walk carries (PDR steps with a
// per-point heading bias and a per-walk stride scale, heading random walk, scale prior, anchors, robust
// Wi-Fi loop closures) as one GraphSLAM-style weighted nonlinear least-squares problem on Ceres.
//
// Model: exactly the cost of analyzer/stridefix_analyzer/crowd/graph.py (its module docstring); the
// scipy twin solve_graph_scipy (crowd/graph_solve.py) minimises the same cost and is the cross-check.
//   unknowns  p_k = (x_k, y_k) [m] and theta_k [rad] per point k = 0..n-1 (theta_k: the rotation from the
//             walk's dead-reckoning frame to the map at that point); s_w per walk w = 0..W-1 (stride scale).
//   step      r = ((p_j - p_i) - s_w R(theta_i) d) / sigma          2 residuals, d = DR displacement i -> j
//   heading   r = (theta_j - theta_i) / sigma                       1 residual (a random walk of the bias)
//   scale     r = (s_w - s0_w) / sigma                              1 residual per walk
//   hprior    r = (theta_k - theta0_k) / sigma                      1 residual (the fleet's heading bias)
//   anchor    r = (p_a - q_a) / sigma                               2 residuals
//   range     r = (b - |p_i - p_j|) / sigma                         1 residual, i and j of different walks
//   cost      = 1/2 sum |r|^2 over step, heading, scale, hprior and anchor rows + 1/2 sum rho(r^2) over range rows,
//   rho       = identity ("none"), or Ceres's HuberLoss / CauchyLoss with scale loss_scale (sigma units),
//               on the range rows ONLY: a fingerprint that looks like a far place must not pull a walk.
// |p_i - p_j| below SF_COORD_MIN_DIST_M: the range Jacobian takes u = (p_i - p_j)/|.| as -x, the
// convention of sf_coord_solver.h (and of the twin), so coincident points are pushed apart, not stuck.
// Every Jacobian is analytic (ceres::SizedCostFunction).
//
// Cost per solve: one sparse Levenberg-Marquardt (SPARSE_NORMAL_CHOLESKY, SuiteSparse) over 3n + W
// unknowns; each iteration is O(rows) to evaluate plus a sparse Cholesky of the normal equations. The
// walks make a band (each point touches its neighbours) and the scale of a walk a dense column of that
// walk; the range rows add the fill of the loop closures. Memory O(n + rows): the unknowns, one cost
// function per row and the factor. No globals; thread-safe for distinct inputs (callers may run several
// solves at once, e.g. from Python threads with the GIL released).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace sf {

// The arrays of crowd/graph.py's GraphProblem; row-major (x, y) for the *_xy_m / step_dxy_m arrays.
struct graph_problem_t {
  int64_t n_points = 0;
  int64_t n_walks = 0;
  std::vector<int64_t> step_i, step_j, step_walk;  // k each; i != j, walk in 0..W-1
  std::vector<double> step_dxy_m;                  // k*2, DR displacement in the walk's own frame
  std::vector<double> step_sigma_m;                // k, > 0
  std::vector<int64_t> head_i, head_j;             // h each; i != j
  std::vector<double> head_sigma_rad;              // h, > 0
  std::vector<double> scale_prior;                 // W, s0 of each walk
  std::vector<double> scale_sigma;                 // W, > 0
  std::vector<int64_t> hprior_idx;                 // p, points with a heading prior
  std::vector<double> hprior_rad;                  // p, theta0 of each
  std::vector<double> hprior_sigma_rad;            // p, > 0
  std::vector<int64_t> anchor_idx;                 // a
  std::vector<double> anchor_xy_m;                 // a*2
  std::vector<double> anchor_sigma_m;              // a, > 0
  std::vector<int64_t> pair_i, pair_j;             // r each; i != j
  std::vector<double> range_m;                     // r, >= 0
  std::vector<double> range_sigma_m;               // r, > 0
  std::string loss = "cauchy";                     // "none" | "huber" | "cauchy" (range rows only)
  double loss_scale = 1.0;                         // in sigma units, > 0
  std::vector<double> init_xy_m;                   // n*2, the start
  std::vector<double> init_heading_rad;            // n
  std::vector<double> init_scale;                  // W
};

struct graph_options_t {
  int max_iterations = 200;
  double function_tolerance = 1e-10;  // Ceres: |d cost| / cost
  double gradient_tolerance = 1e-12;  // Ceres: max-norm of the gradient
  double parameter_tolerance = 1e-10; // Ceres: |dx| / (|x| + tol)
  int num_threads = 1;
};

struct graph_result_t {
  std::vector<double> xy_m;           // n*2 row-major
  std::vector<double> heading_rad;    // n
  std::vector<double> scale;          // W
  double cost = 0.0;                  // final cost, as defined above
  double initial_cost = 0.0;
  int iterations = 0;                 // Ceres iterations (successful + unsuccessful steps)
  bool converged = false;             // terminated by a tolerance (Ceres CONVERGENCE)
  double time_s = 0.0;                // Ceres total wall time
  std::string message;                // Ceres termination message
};

// Checks every input (shapes, index ranges, i != j on every two-point row, sigmas > 0 and finite,
// finite values, the loss name and scale, the options) and throws std::invalid_argument listing ALL
// the problems found.
void sf_graph_validate(const graph_problem_t& problem, const graph_options_t& options = {});

// Solves from the problem's start. Throws std::invalid_argument on bad input, std::runtime_error when
// Ceres fails.
graph_result_t sf_graph_solve(const graph_problem_t& problem, const graph_options_t& options);

}  // namespace sf
