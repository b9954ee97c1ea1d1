#include "isoflex/elements/beam_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace isoflex::elements {

namespace {

// The right-handed triad with d₃ = tangent (unit) and d₁ along the part of the hint orthogonal
// to it. A hint within ~0.06° of the tangent would leave a d₁ dominated by round-off, so it is
// refused rather than silently repaired.
Mat3 triad_along(const Vec3& tangent, const Vec3& d1_hint, const char* who) {
  const Vec3 d1_raw = d1_hint - d1_hint.dot(tangent) * tangent;
  if (!(d1_raw.norm() > 1e-3 * d1_hint.norm()))
    throw std::invalid_argument(std::string(who) + ": d1 hint is parallel to the beam axis");
  Mat3 R;
  R.col(0) = d1_raw.normalized();
  R.col(2) = tangent;
  R.col(1) = tangent.cross(R.col(0));
  return R;
}

}  // namespace

std::vector<frame_node::Q> straight_beam_nodes(const Vec3& start, const Vec3& end,
                                               const Vec3& d1_hint, int n_elements) {
  if (!(n_elements >= 1))
    throw std::invalid_argument("straight_beam_nodes: need at least one element, got " +
                                std::to_string(n_elements));
  const Vec3 axis = end - start;
  const double length = axis.norm();
  if (!(length > 0.0)) throw std::invalid_argument("straight_beam_nodes: start and end coincide");
  const Mat3 R = triad_along(axis / length, d1_hint, "straight_beam_nodes");

  std::vector<frame_node::Q> nodes;
  nodes.reserve(n_elements + 1);
  for (int i = 0; i <= n_elements; ++i) {
    const double t = static_cast<double>(i) / n_elements;
    nodes.push_back(frame_node::make((1.0 - t) * start + t * end, R));
  }
  return nodes;
}

std::vector<frame_node::Q> helix_beam_nodes(const Vec3& axis_point, const Vec3& axis,
                                            const Vec3& start, double angle, double pitch,
                                            const Vec3& d1_hint, int n_elements) {
  if (!(n_elements >= 1))
    throw std::invalid_argument("helix_beam_nodes: need at least one element, got " +
                                std::to_string(n_elements));
  if (!(angle > 0.0)) throw std::invalid_argument("helix_beam_nodes: the angle must be > 0");
  const Vec3 n = axis.normalized();
  const Vec3 r0 = start - axis_point;
  const Vec3 radius = r0 - r0.dot(n) * n;  // from the axis to the start, orthogonal to it
  if (!(radius.norm() > 1e-12 * std::max(r0.norm(), 1.0)))
    throw std::invalid_argument("helix_beam_nodes: the start point lies on the axis");
  // dx/dθ at θ = 0: n × radius (turning) + pitch/(2π) n (rising).
  const Vec3 tangent = (n.cross(radius) + pitch / (2.0 * M_PI) * n).normalized();
  const Mat3 D0 = triad_along(tangent, d1_hint, "helix_beam_nodes");
  const Vec3 foot = start - radius;  // the axis point level with the start

  std::vector<frame_node::Q> nodes;
  nodes.reserve(n_elements + 1);
  for (int i = 0; i <= n_elements; ++i) {
    const double theta = angle * i / n_elements;
    const Mat3 R = Eigen::AngleAxisd(theta, n).toRotationMatrix();
    nodes.push_back(frame_node::make(foot + R * radius + pitch * theta / (2.0 * M_PI) * n, R * D0));
  }
  return nodes;
}

}  // namespace isoflex::elements
