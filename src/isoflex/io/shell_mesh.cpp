#include "isoflex/io/shell_mesh.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace isoflex::io {

ShellMesh shell_mesh(const integrate::Snapshot& s, const std::vector<Vec3>& reference_positions) {
  const std::size_t n_nodes = s.bodies.size();
  // local[i]: the point of node i, −1 while node i is not used by any element.
  std::vector<int> local(n_nodes, -1);
  for (const auto& e : s.shell_elements) {
    for (const int a : e.nodes) {
      if (a < 0 || static_cast<std::size_t>(a) >= n_nodes) {
        throw std::runtime_error(fmt::format(
            "VTK output: element {} of shell \"{}\" has node {}; the snapshot has {} nodes",
            e.element, e.shell, a, n_nodes));
      }
      if (static_cast<std::size_t>(a) >= reference_positions.size()) {
        throw std::runtime_error(fmt::format(
            "VTK output: shell node {} has no position at t = 0 (the first snapshot has {} nodes)",
            a, reference_positions.size()));
      }
      local[a] = 0;
    }
  }
  ShellMesh out;
  for (std::size_t i = 0; i < n_nodes; ++i) {
    if (local[i] < 0) continue;
    local[i] = static_cast<int>(out.nodes.size());
    const integrate::BodyPose& p = s.bodies[i];
    out.nodes.push_back(static_cast<int>(i));
    out.mesh.points.push_back(p.position);
    out.mesh.velocities.push_back(p.velocity);
    out.displacements.push_back(p.position - reference_positions[i]);
    out.directors.push_back(p.directors.col(2));
  }
  for (const auto& e : s.shell_elements) {
    for (const int a : e.nodes) out.mesh.connectivity.push_back(local[a]);
    out.mesh.offsets.push_back(static_cast<int>(out.mesh.connectivity.size()));
    out.mesh.types.push_back(kVtkQuad);
    out.mesh.parts.push_back(kShellPart);
  }
  return out;
}

double von_mises(const Eigen::Matrix2d& a) {
  const double a11 = a(0, 0), a22 = a(1, 1), a12 = 0.5 * (a(0, 1) + a(1, 0));
  // The sum is a positive semi-definite quadratic form; max(0, ·) only absorbs round-off.
  return std::sqrt(std::max(0.0, a11 * a11 + a22 * a22 - a11 * a22 + 3.0 * a12 * a12));
}

}  // namespace isoflex::io
