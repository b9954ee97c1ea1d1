// Spring–dampers between material points (model `springs`, elements/point_spring_damper.hpp):
// each end's point as a linear map of its nodes' coordinates, x = P q_e + c, from the probe
// machinery (System::probe_gradient: the points are linear in the coordinates); a spring's
// actuator is a load on the same nodes (loads/line_actuator.hpp).
#include <fmt/format.h>

#include <algorithm>
#include <cassert>
#include <map>

#include "isoflex/elements/point_spring_damper.hpp"
#include "isoflex/loads/line_actuator.hpp"
#include "isoflex/system/compile_error.hpp"
#include "isoflex/system/system.hpp"

namespace isoflex::system {

void System::add_springs(const model::Model& m, const NodeFinder& find) {
  for (std::size_t k = 0; k < m.springs.size(); ++k) {
    const model::Spring& S = m.springs[k];
    const std::string what = fmt::format("springs[{}]", k);
    // The ends as probe instances (none for a point of the ground).
    const auto instance = [&](const model::Probe& P,
                              const char* end) -> std::optional<ProbeInstance> {
      if (!P.kl_shell.empty()) return kl_probe(P);
      const int node = find(P.body, S.source, fmt::format("{}.{}.body", what, end));
      if (node < 0) return std::nullopt;
      return ProbeInstance{S.name, node, body_coordinates(node, P.point, P.point_local), {}};
    };
    const std::optional<ProbeInstance> ends[2] = {instance(S.a, "a"), instance(S.b, "b")};
    std::vector<int> nodes;
    for (const auto& e : ends) {
      if (!e) continue;
      std::vector<int> of = e->weights.empty() ? std::vector<int>{e->node} : std::vector<int>{};
      for (const auto& [node, w] : e->weights) of.push_back(node);
      for (int a : of)
        if (std::find(nodes.begin(), nodes.end(), a) == nodes.end()) nodes.push_back(a);
    }
    std::map<int, int> column;  // global coordinate → stacked column
    int n = 0;
    for (int a : nodes)
      for (int j = 0; j < coordinate_count(a); ++j) column[q_offset(a) + j] = n++;
    const VecX q0e = stacked(q0_, nodes);
    elements::MaterialPointMap maps[2];
    for (int e = 0; e < 2; ++e) {
      maps[e].P = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, n);
      if (!ends[e]) {
        maps[e].c = *(e == 0 ? S.a : S.b).point;
        continue;
      }
      for (int r = 0; r < 3; ++r)
        for (const auto& [i, v] : probe_gradient(*ends[e], Vec3::Unit(r)))
          maps[e].P(r, column.at(i)) = v;
      maps[e].c = probe_point(q0_, *ends[e]) - maps[e].P * q0e;
    }
    const double distance = ((maps[0].P - maps[1].P) * q0e + maps[0].c - maps[1].c).norm();
    const elements::SpringDamperLaw law{S.stiffness, S.damping, S.free_length.value_or(distance),
                                        S.stiffness_law, S.damping_law};
    try {
      auto element =
          std::make_unique<elements::PointSpringDamper>(nodes, n, maps[0], maps[1], law, q0e);
      viscous_ = viscous_ || element->viscous();
      springs_.push_back(
          {S.name, static_cast<int>(elements_.size()), -1, !ends[0] ? 0 : (!ends[1] ? 1 : -1)});
      elements_.push_back(std::move(element));
      if (!S.actuator.empty()) {
        springs_.back().actuator_load = static_cast<int>(loads_.size());
        loads_.push_back(std::make_shared<loads::LineActuator>(
            nodes, maps[0].P - maps[1].P, maps[0].c - maps[1].c, loads::TimeFunction(S.actuator),
            q0e));
      }
    } catch (const std::invalid_argument& e) {
      compile_fail(S.source, what, e.what());
    }
  }
}

void System::move_spring_anchor(int s, const Vec3& point, const Vec3& velocity) {
  const SpringInstance& S = springs_.at(static_cast<std::size_t>(s));
  assert(S.ground_end >= 0);
  static_cast<elements::PointSpringDamper&>(*elements_[static_cast<std::size_t>(S.element_index)])
      .move_anchor(S.ground_end, point, velocity);
}

}  // namespace isoflex::system
