#pragma once
// Fixed-size Eigen types used in every kernel.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>

namespace isoflex {
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using VecX = Eigen::VectorXd;
using MatX = Eigen::MatrixXd;
template <int R, int C>
using Mat = Eigen::Matrix<double, R, C>;
template <int N>
using Vec = Eigen::Matrix<double, N, 1>;
}  // namespace isoflex
