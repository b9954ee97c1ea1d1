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

// A circular arc or a helix (docs/theory/beam.md §10): the curve swept by `start` turning about
// the axis through `axis_point` along the unit `axis` by θ ∈ [0, angle] (radians, right-handed
// about `axis`) while rising `pitch` along the axis per full turn,
//   x(θ) = a + R(θ) (start − a) + pitch θ/(2π) axis,
// with nodes at equal steps of θ (equal arc length). The triad at θ is the one at θ = 0 turned by
// the same rotation R(θ) — the screw motion that maps the curve onto itself — so d₃ is the exact
// unit tangent at every node and the section keeps its orientation relative to the radius (for a
// plane arc this is the frame carried along without twist). At θ = 0: d₃ the tangent, d₁ the part
// of `d1_hint` orthogonal to it, d₂ = d₃ × d₁. Throws std::invalid_argument if start lies on the
// axis, angle ≤ 0, n_elements < 1, or d1_hint is (nearly) parallel to the start tangent.
std::vector<frame_node::Q> helix_beam_nodes(const Vec3& axis_point, const Vec3& axis,
                                            const Vec3& start, double angle, double pitch,
                                            const Vec3& d1_hint, int n_elements);

}  // namespace isoflex::elements
