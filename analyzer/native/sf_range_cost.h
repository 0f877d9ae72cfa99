// sf_range_cost.h - the range row both Ceres solvers share: r = w * (b - |p_I - p_J|), with the
// coincident-points convention of sf_coord_solver.h (u = -x below SF_COORD_MIN_DIST_M). The coordinate
// solver (sf_coord_solver.cpp) passes the thesis's w = 1/(m*b + c); the crowd graph (sf_graph_solver.cpp)
// passes w = 1/sigma. Cost: one hypot per evaluation; no memory beyond the two doubles.
#pragma once

#include <ceres/ceres.h>

#include <cmath>

#include "sf_coord_solver.h"

namespace sf {

// Range row: r = w * (b - |p_I - p_J|). dr/dp_I = -w * u, dr/dp_J = +w * u, u = (p_I - p_J) / |.|;
// u = -x (p_J east of p_I) when the points (nearly) coincide - see the header.
class range_cost final : public ceres::SizedCostFunction<1, 2, 2> {
 public:
  range_cost(double range_m, double weight_per_m) : range_m_(range_m), weight_per_m_(weight_per_m) {}
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const double* pi = parameters[0];
    const double* pj = parameters[1];
    const double dx = pi[0] - pj[0];
    const double dy = pi[1] - pj[1];
    const double d = std::hypot(dx, dy);
    residuals[0] = weight_per_m_ * (range_m_ - d);
    if (jacobians != nullptr) {
      double ux = -1.0;
      double uy = 0.0;
      if (d >= SF_COORD_MIN_DIST_M) {
        ux = dx / d;
        uy = dy / d;
      }
      if (jacobians[0] != nullptr) {
        jacobians[0][0] = -weight_per_m_ * ux;
        jacobians[0][1] = -weight_per_m_ * uy;
      }
      if (jacobians[1] != nullptr) {
        jacobians[1][0] = weight_per_m_ * ux;
        jacobians[1][1] = weight_per_m_ * uy;
      }
    }
    return true;
  }

 private:
  const double range_m_;
  const double weight_per_m_;
};

}  // namespace sf
