// sf_native_module.cpp - the Python module stridefix_native (pybind11) over sf_coord_solver.h and
// sf_graph_solver.h. Inputs are checked here for shape and dtype, then by sf_coord_validate /
// sf_graph_validate for values; every problem found is listed in one ValueError.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "sf_coord_solver.h"
#include "sf_graph_solver.h"

namespace py = pybind11;

namespace {

std::string shape_str(const py::array& a) {
  std::ostringstream os;
  os << "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) os << (d ? ", " : "") << a.shape(d);
  os << (a.ndim() == 1 ? ",)" : ")");
  return os.str();
}

// Reads obj as a (rows x cols) array (cols == 0: a 1-D array). An empty input is taken as zero rows.
template <typename T>
std::vector<T> read_array(py::handle obj, const char* name, py::ssize_t cols, bool integer,
                          std::vector<std::string>& problems) {
  py::array a = py::array::ensure(obj);
  if (!a) {
    problems.push_back(std::string(name) + " is not array-like");
    PyErr_Clear();
    return {};
  }
  if (a.size() == 0) return {};
  const bool shape_ok = cols == 0 ? a.ndim() == 1 : (a.ndim() == 2 && a.shape(1) == cols);
  if (!shape_ok) {
    problems.push_back(std::string(name) + " must have shape " + (cols == 0 ? "(m,)" : "(rows, 2)") + ", got " +
                       shape_str(a));
    return {};
  }
  const char kind = a.dtype().kind();
  if (integer && kind != 'i' && kind != 'u') {
    problems.push_back(std::string(name) + " must hold integers, got dtype kind '" + std::string(1, kind) + "'");
    return {};
  }
  if (!integer && kind != 'f' && kind != 'i' && kind != 'u') {
    problems.push_back(std::string(name) + " must hold numbers, got dtype kind '" + std::string(1, kind) + "'");
    return {};
  }
  auto c = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(a);
  return std::vector<T>(c.data(), c.data() + c.size());
}

// The Ceres summary both solvers return (coord_result_t and graph_result_t share these fields).
template <typename Result>
void put_summary(py::dict& out, const Result& res) {
  out["cost"] = res.cost;
  out["initial_cost"] = res.initial_cost;
  out["iterations"] = res.iterations;
  out["converged"] = res.converged;
  out["time_s"] = res.time_s;
  out["message"] = res.message;
}

py::array_t<double> as_xy(const std::vector<double>& xy) {
  const auto n = static_cast<py::ssize_t>(xy.size() / 2);
  py::array_t<double> out({n, static_cast<py::ssize_t>(2)});
  std::copy(xy.begin(), xy.end(), out.mutable_data());
  return out;
}

sf::robust_loss parse_loss(const std::string& name) {
  if (name == "none" || name == "linear") return sf::robust_loss::none;
  if (name == "huber") return sf::robust_loss::huber;
  if (name == "cauchy") return sf::robust_loss::cauchy;
  throw std::invalid_argument("robust_loss must be 'none', 'huber' or 'cauchy', got '" + name + "'");
}

py::dict solve_coordinates(int64_t n_points, py::handle anchors_idx, py::handle anchors_xy, py::handle pairs,
                           py::handle ranges_m, py::handle weights, py::object weight_slope,
                           py::object weight_intercept_m, py::handle init_xy, const std::string& robust_loss,
                           double loss_scale, int max_iterations, double function_tolerance,
                           double gradient_tolerance, double parameter_tolerance, int num_threads,
                           bool full_report) {
  std::vector<std::string> problems;
  sf::coord_problem_t pr;
  pr.n_points = n_points;
  pr.anchor_idx = read_array<int64_t>(anchors_idx, "anchors_idx", 0, true, problems);
  pr.anchor_xy_m = read_array<double>(anchors_xy, "anchors_xy", 2, false, problems);
  pr.pair_idx = read_array<int64_t>(pairs, "pairs", 2, true, problems);
  pr.range_m = read_array<double>(ranges_m, "ranges_m", 0, false, problems);
  std::vector<double> init;
  if (!init_xy.is_none()) init = read_array<double>(init_xy, "init_xy", 2, false, problems);
  const bool law_given = !weight_slope.is_none() || !weight_intercept_m.is_none();
  if (!weights.is_none()) {
    if (law_given) problems.push_back("pass either weights or weight_slope/weight_intercept_m, not both");
    pr.weight_per_m = read_array<double>(weights, "weights", 0, false, problems);
  }
  if (!problems.empty()) {
    std::ostringstream os;
    os << "solve_coordinates: " << problems.size() << " problem(s) with the input:";
    for (const auto& p : problems) os << "\n  - " << p;
    throw std::invalid_argument(os.str());
  }
  if (weights.is_none()) {
    const double m = weight_slope.is_none() ? 1.0 : weight_slope.cast<double>();
    const double c = weight_intercept_m.is_none() ? 2.0 : weight_intercept_m.cast<double>();
    // Bad ranges are reported by the full check below, with everything else; the law only when they pass.
    pr.weight_per_m.assign(pr.range_m.size(), 1.0);
    sf::sf_coord_validate(pr, init);
    pr.weight_per_m = sf::sf_coord_weights(pr.range_m, m, c);
  }

  sf::coord_options_t opt;
  opt.loss = parse_loss(robust_loss);
  opt.loss_scale = loss_scale;
  opt.max_iterations = max_iterations;
  opt.function_tolerance = function_tolerance;
  opt.gradient_tolerance = gradient_tolerance;
  opt.parameter_tolerance = parameter_tolerance;
  opt.num_threads = num_threads;
  opt.full_report = full_report;

  sf::coord_result_t res;
  {
    py::gil_scoped_release release;
    res = sf::sf_coord_solve(pr, init, opt);
  }
  py::dict out;
  out["xy"] = as_xy(res.xy_m);
  put_summary(out, res);
  out["weights"] = py::array_t<double>(static_cast<py::ssize_t>(pr.weight_per_m.size()), pr.weight_per_m.data());
  if (full_report) out["report"] = res.report;
  return out;
}

py::array_t<double> default_init(int64_t n_points, py::handle anchors_idx, py::handle anchors_xy) {
  std::vector<std::string> problems;
  const auto idx = read_array<int64_t>(anchors_idx, "anchors_idx", 0, true, problems);
  const auto xy = read_array<double>(anchors_xy, "anchors_xy", 2, false, problems);
  if (!problems.empty()) throw std::invalid_argument("default_init: " + problems.front());
  return as_xy(sf::sf_coord_default_init(n_points, idx, xy));
}

py::array_t<double> thesis_weights(py::handle ranges_m, double weight_slope, double weight_intercept_m) {
  std::vector<std::string> problems;
  const auto b = read_array<double>(ranges_m, "ranges_m", 0, false, problems);
  if (!problems.empty()) throw std::invalid_argument("thesis_weights: " + problems.front());
  const auto w = sf::sf_coord_weights(b, weight_slope, weight_intercept_m);
  return py::array_t<double>(static_cast<py::ssize_t>(w.size()), w.data());
}

py::array_t<double> as_vec(const std::vector<double>& v) {
  py::array_t<double> out(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), out.mutable_data());
  return out;
}

// stridefix_native.solve_graph: the crowd graph of crowd/graph.py (GraphProblem's arrays, in its order).
py::dict solve_graph(int64_t n_points, int64_t n_walks, py::handle step_i, py::handle step_j, py::handle step_walk,
                     py::handle step_dxy_m, py::handle step_sigma_m, py::handle head_i, py::handle head_j,
                     py::handle head_sigma_rad, py::handle scale_prior, py::handle scale_sigma,
                     py::handle hprior_idx, py::handle hprior_rad, py::handle hprior_sigma_rad,
                     py::handle anchor_idx, py::handle anchor_xy_m, py::handle anchor_sigma_m, py::handle pair_i,
                     py::handle pair_j, py::handle range_m, py::handle range_sigma_m, const std::string& loss,
                     double loss_scale, py::handle init_xy, py::handle init_heading_rad, py::handle init_scale,
                     int max_iterations, int num_threads) {
  std::vector<std::string> problems;
  sf::graph_problem_t g;
  g.n_points = n_points;
  g.n_walks = n_walks;
  g.step_i = read_array<int64_t>(step_i, "step_i", 0, true, problems);
  g.step_j = read_array<int64_t>(step_j, "step_j", 0, true, problems);
  g.step_walk = read_array<int64_t>(step_walk, "step_walk", 0, true, problems);
  g.step_dxy_m = read_array<double>(step_dxy_m, "step_dxy_m", 2, false, problems);
  g.step_sigma_m = read_array<double>(step_sigma_m, "step_sigma_m", 0, false, problems);
  g.head_i = read_array<int64_t>(head_i, "head_i", 0, true, problems);
  g.head_j = read_array<int64_t>(head_j, "head_j", 0, true, problems);
  g.head_sigma_rad = read_array<double>(head_sigma_rad, "head_sigma_rad", 0, false, problems);
  g.scale_prior = read_array<double>(scale_prior, "scale_prior", 0, false, problems);
  g.scale_sigma = read_array<double>(scale_sigma, "scale_sigma", 0, false, problems);
  g.hprior_idx = read_array<int64_t>(hprior_idx, "hprior_idx", 0, true, problems);
  g.hprior_rad = read_array<double>(hprior_rad, "hprior_rad", 0, false, problems);
  g.hprior_sigma_rad = read_array<double>(hprior_sigma_rad, "hprior_sigma_rad", 0, false, problems);
  g.anchor_idx = read_array<int64_t>(anchor_idx, "anchor_idx", 0, true, problems);
  g.anchor_xy_m = read_array<double>(anchor_xy_m, "anchor_xy_m", 2, false, problems);
  g.anchor_sigma_m = read_array<double>(anchor_sigma_m, "anchor_sigma_m", 0, false, problems);
  g.pair_i = read_array<int64_t>(pair_i, "pair_i", 0, true, problems);
  g.pair_j = read_array<int64_t>(pair_j, "pair_j", 0, true, problems);
  g.range_m = read_array<double>(range_m, "range_m", 0, false, problems);
  g.range_sigma_m = read_array<double>(range_sigma_m, "range_sigma_m", 0, false, problems);
  g.init_xy_m = read_array<double>(init_xy, "init_xy", 2, false, problems);
  g.init_heading_rad = read_array<double>(init_heading_rad, "init_heading_rad", 0, false, problems);
  g.init_scale = read_array<double>(init_scale, "init_scale", 0, false, problems);
  g.loss = loss == "linear" ? "none" : loss;
  g.loss_scale = loss_scale;
  if (!problems.empty()) {
    std::ostringstream os;
    os << "solve_graph: " << problems.size() << " problem(s) with the input:";
    for (const auto& p : problems) os << "\n  - " << p;
    throw std::invalid_argument(os.str());
  }
  sf::graph_options_t opt;
  opt.max_iterations = max_iterations;
  opt.num_threads = num_threads;

  sf::graph_result_t res;
  {
    py::gil_scoped_release release;  // the inputs are copied: other Python threads may run (and solve)
    res = sf::sf_graph_solve(g, opt);
  }
  py::dict out;
  out["xy"] = as_xy(res.xy_m);
  out["heading_rad"] = as_vec(res.heading_rad);
  out["scale"] = as_vec(res.scale);
  put_summary(out, res);
  return out;
}

}  // namespace

PYBIND11_MODULE(stridefix_native, mod) {
  mod.doc() =
      "StrideFix native code. The Kannan (2024) coordinate solver: 2-D positions from anchors and weighted "
      "pairwise ranges, by nonlinear least squares on Ceres (analyzer/native/sf_coord_solver.h); and the crowd "
      "graph solver: PDR steps, heading and scale, anchors and robust Wi-Fi ranges (sf_graph_solver.h).";
  mod.def("solve_coordinates", &solve_coordinates, py::arg("n_points"), py::arg("anchors_idx"),
          py::arg("anchors_xy"), py::arg("pairs"), py::arg("ranges_m"), py::arg("weights") = py::none(),
          py::kw_only(), py::arg("weight_slope") = py::none(), py::arg("weight_intercept_m") = py::none(),
          py::arg("init_xy") = py::none(), py::arg("robust_loss") = "none", py::arg("loss_scale") = 1.0,
          py::arg("max_iterations") = 200, py::arg("function_tolerance") = 1e-10,
          py::arg("gradient_tolerance") = 1e-12, py::arg("parameter_tolerance") = 1e-10,
          py::arg("num_threads") = 1, py::arg("full_report") = false,
          R"(Solve the 2-D coordinates of n_points points (Kannan 2024, thesis section 4).

Minimises 1/2 sum |p_i - a_i|^2 over anchors + 1/2 sum rho((w_k (b_k - |p_I - p_J|))^2) over pairs.

Parameters
----------
n_points : int
anchors_idx : (k,) int array, anchored point indices (several anchors on one point are allowed).
anchors_xy : (k, 2) float array, anchor positions in metres.
pairs : (m, 2) int array, point index pairs (I, J), I != J.
ranges_m : (m,) float array, observed pair distances b_k >= 0 in metres.
weights : (m,) float array or None, explicit residual multipliers w_k > 0 (1/m). When None, the thesis
    law w_k = 1 / (weight_slope * b_k + weight_intercept_m) is used (default slope 1, intercept 2 m).
init_xy : (n_points, 2) float array or None, the start. None: anchors at their positions, other points
    interpolated linearly in index order between the nearest anchors, held constant beyond the ends.
robust_loss : 'none' | 'huber' | 'cauchy', on the range rows only, with scale loss_scale (residual units).
max_iterations, function_tolerance, gradient_tolerance, parameter_tolerance : Ceres stopping rules.
num_threads : Ceres evaluation threads.
full_report : also return Ceres's FullReport() (stage timings, linear solver) as report.

Returns
-------
dict with xy (n_points, 2) metres, cost (final, 1/2 sum rho), initial_cost, iterations, converged (bool,
a tolerance was met), time_s (Ceres wall time), message (Ceres), weights (m,) the w_k used.

Raises ValueError listing every problem with the input.)");
  mod.def("default_init", &default_init, py::arg("n_points"), py::arg("anchors_idx"), py::arg("anchors_xy"),
          "The default start of solve_coordinates as an (n_points, 2) array (needs >= 1 anchor).");
  mod.def("thesis_weights", &thesis_weights, py::arg("ranges_m"), py::arg("weight_slope") = 1.0,
          py::arg("weight_intercept_m") = 2.0,
          "w_k = 1 / (weight_slope * b_k + weight_intercept_m); ValueError unless every w_k is positive, finite.");
  mod.def("solve_graph", &solve_graph, py::arg("n_points"), py::arg("n_walks"), py::arg("step_i"), py::arg("step_j"),
          py::arg("step_walk"), py::arg("step_dxy_m"), py::arg("step_sigma_m"), py::arg("head_i"), py::arg("head_j"),
          py::arg("head_sigma_rad"), py::arg("scale_prior"), py::arg("scale_sigma"), py::arg("hprior_idx"),
          py::arg("hprior_rad"), py::arg("hprior_sigma_rad"), py::arg("anchor_idx"),
          py::arg("anchor_xy_m"), py::arg("anchor_sigma_m"), py::arg("pair_i"), py::arg("pair_j"),
          py::arg("range_m"), py::arg("range_sigma_m"), py::kw_only(), py::arg("loss") = "cauchy",
          py::arg("loss_scale") = 1.0, py::arg("init_xy"), py::arg("init_heading_rad"), py::arg("init_scale"),
          py::arg("max_iterations") = 200, py::arg("num_threads") = 1,
          R"(Solve the crowd graph (analyzer/stridefix_analyzer/crowd/graph.py; model in sf_graph_solver.h).

Unknowns: p_k (x, y) [m] and heading bias theta_k [rad] per point, stride scale s_w per walk. Minimises
1/2 sum |r|^2 over step rows ((p_j - p_i) - s_w R(theta_i) d)/sigma, heading rows (theta_j - theta_i)/sigma,
scale rows (s_w - s0_w)/sigma, heading-prior rows (theta_k - theta0_k)/sigma and anchor rows (p_a - q_a)/sigma, plus 1/2 sum rho(r^2) over range rows
(b - |p_i - p_j|)/sigma, rho the robust loss ('none' | 'huber' | 'cauchy', scale loss_scale) on those only.

Parameters are GraphProblem's arrays (k steps, h heading rows, W walks, p heading priors, a anchors, r pairs): step_i, step_j,
step_walk (k,) int; step_dxy_m (k, 2); step_sigma_m (k,); head_i, head_j (h,) int; head_sigma_rad (h,);
scale_prior, scale_sigma (W,); hprior_idx (p,) int; hprior_rad, hprior_sigma_rad (p,); anchor_idx (a,) int; anchor_xy_m (a, 2); anchor_sigma_m (a,); pair_i, pair_j
(r,) int; range_m, range_sigma_m (r,). Empty arrays are fine (e.g. no pairs). The start: init_xy (n, 2),
init_heading_rad (n,), init_scale (W,). max_iterations: Ceres LM iterations; num_threads: Ceres threads.
The GIL is released during the solve.

Returns dict(xy (n, 2), heading_rad (n,), scale (W,), cost, initial_cost, iterations, converged, time_s,
message). Raises ValueError listing every problem with the input.)");
  mod.attr("MIN_DIST_M") = sf::SF_COORD_MIN_DIST_M;
}
