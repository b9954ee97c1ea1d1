#include "support/kl_static_problem.hpp"

#include <fmt/format.h>

#include <stdexcept>
#include <utility>

namespace isoflex::test {

using integrate::ResidualEvaluation;
using integrate::StaticProblem;

StaticProblem kl_static_problem(const elements::KLShellPatch& patch, PatchLoads loads,
                                elements::KLKinematics kinematics) {
  StaticProblem pb;
  pb.reference = patch.reference_positions();
  bool follower = false;
  for (std::size_t i = 0; i < loads.size(); ++i) {
    if (!loads[i])
      throw std::invalid_argument(fmt::format("kl_static_problem: load {} is null", i));
    if (loads[i]->follower()) {
      follower = true;
    } else if (loads[i]->force(pb.reference).size() != pb.reference.size()) {
      throw std::invalid_argument(
          fmt::format("kl_static_problem: load {} has {} dofs, the patch {}", i,
                      loads[i]->force(pb.reference).size(), pb.reference.size()));
    }
  }
  pb.symmetric = !follower;
  pb.linear = kinematics == elements::KLKinematics::linear && !follower;
  const elements::KLShellPatch* P = &patch;
  pb.evaluate = [P, loads = std::move(loads), kinematics](
                    const VecX& x, double t, bool with_tangent, ResidualEvaluation& out) {
    out.r = P->internal_force(x, kinematics, with_tangent ? &out.K : nullptr);
    VecX fext = VecX::Zero(x.size());
    for (const auto& L : loads) {
      const double lam = L->factor(t);
      if (lam == 0.0) continue;
      fext += lam * L->force(x);
      if (with_tangent && L->follower()) L->add_tangent(x, -lam, out.K);
    }
    out.r -= fext;
    out.load_norm = fext.size() ? fext.lpNorm<Eigen::Infinity>() : 0.0;
  };
  return pb;
}

}  // namespace isoflex::test
