#pragma once
// The known Eq. (2) coefficients the fit tests simulate from (test_guo2006.cpp and
// test_guo2006_coverage.cpp): magnitudes of a navigation-grade gyro's thermal bias.

#include <Eigen/Dense>

namespace rlg::model {

inline Eigen::Matrix3d TrueA() {
  Eigen::Matrix3d A;
  A << 0.010, 2.0e-4, -3.0e-6,  // a1: °/h per °C
      -0.004, 5.0e-5, 1.0e-6,   // a2: °/h per °C²
      0.300, 2.0e-3, -1.0e-5;   // a3: °/h per °C of gradient
  return A;
}

}  // namespace rlg::model
