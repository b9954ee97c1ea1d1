#pragma once
// Reference nodes of a straight beam (docs/theory/beam.md §7): equally spaced frame nodes from
// `start` to `end` with the same orthonormal triad at every node, d₃ along the axis (the
// convention of DNSM-III §3.1: d₃ tangent to the line of centroids in the reference), d₁ the part
// of `d1_hint` orthogonal to the axis, d₂ = d₃ × d₁ (right-handed).
#include <vector>

#include "isoflex/math/frame_node.hpp"

namespace isoflex::elements {

// Returns n_elements + 1 nodes. Throws std::invalid_argument if start = end, n_elements < 1, or
// d1_hint is (nearly) parallel to the axis.
std::vector<frame_node::Q> straight_beam_nodes(const Vec3& start, const Vec3& end,
                                               const Vec3& d1_hint, int n_elements);

}  // namespace isoflex::elements
