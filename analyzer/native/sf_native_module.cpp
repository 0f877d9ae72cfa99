// sf_native_module.cpp - the Python module stridefix_native (pybind11) over sf_coord_solver.h.
// Inputs are checked here for shape and dtype, then by sf_coord_validate for values; every problem found
// is listed in one ValueError.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "sf_coord_solver.h"

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
  out["cost"] = res.cost;
  out["initial_cost"] = res.initial_cost;
  out["iterations"] = res.iterations;
  out["converged"] = res.converged;
  out["time_s"] = res.time_s;
  out["message"] = res.message;
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

}  // namespace

PYBIND11_MODULE(stridefix_native, mod) {
  mod.doc() =
      "StrideFix native code. The Kannan (2024) coordinate solver: 2-D positions from anchors and weighted "
      "pairwise ranges, by nonlinear least squares on Ceres. The model is in analyzer/native/sf_coord_solver.h.";
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
  mod.attr("MIN_DIST_M") = sf::SF_COORD_MIN_DIST_M;
}
