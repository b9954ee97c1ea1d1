#include "isoflex/elements/beam_mesh.hpp"

#include <stdexcept>
#include <string>

namespace isoflex::elements {

std::vector<frame_node::Q> straight_beam_nodes(const Vec3& start, const Vec3& end,
                                               const Vec3& d1_hint, int n_elements) {
  if (!(n_elements >= 1))
    throw std::invalid_argument("straight_beam_nodes: need at least one element, got " +
                                std::to_string(n_elements));
  const Vec3 axis = end - start;
  const double length = axis.norm();
  if (!(length > 0.0)) throw std::invalid_argument("straight_beam_nodes: start and end coincide");
  const Vec3 d3 = axis / length;
  // Gram–Schmidt: d₁ is the hint with its axial part removed. A hint within ~0.06° of the axis
  // would leave a d₁ dominated by round-off, so it is refused rather than silently repaired.
  const Vec3 d1_raw = d1_hint - d1_hint.dot(d3) * d3;
  if (!(d1_raw.norm() > 1e-3 * d1_hint.norm()))
    throw std::invalid_argument("straight_beam_nodes: d1 hint is parallel to the beam axis");
  Mat3 R;
  R.col(0) = d1_raw.normalized();
  R.col(2) = d3;
  R.col(1) = d3.cross(R.col(0));

  std::vector<frame_node::Q> nodes;
  nodes.reserve(n_elements + 1);
  for (int i = 0; i <= n_elements; ++i) {
    const double t = static_cast<double>(i) / n_elements;
    nodes.push_back(frame_node::make((1.0 - t) * start + t * end, R));
  }
  return nodes;
}

}  // namespace isoflex::elements
