#include "isoflex/system/tree_newton_solver.hpp"

#include <Eigen/LU>
#include <stdexcept>

#include "isoflex/math/frame_node.hpp"
#include "isoflex/math/rotation.hpp"

namespace isoflex::system {

namespace fn = frame_node;
using Mat6 = Mat<6, 6>;
using Block6r = Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, 6>;
using Blockr6 = Eigen::Matrix<double, Eigen::Dynamic, 6, 0, 6, 6>;
using Blockrr = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;
using Vecr = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;

TreeNewtonSolver::TreeNewtonSolver(const System& sys)
    : sys_(sys), link_of_node_(sys.node_count(), -1) {
  if (!sys.frame_nodes_only()) return;  // the recursion is written for frame nodes
  for (std::size_t r = 0; r < sys.roots().size(); ++r)
    links_.push_back({sys.roots()[r], -1, -1, sys.root_nu_offsets()[r], 6, 3});
  for (int j : sys.tree_order()) {
    const auto& J = sys.joints()[j];
    links_.push_back({J.child, J.parent, j, J.nu_offset, J.frame->freedom_count(),
                      J.frame->rotation_vector_offset()});
  }
  for (std::size_t l = 0; l < links_.size(); ++l)
    link_of_node_[links_[l].node] = static_cast<int>(l);
}

bool TreeNewtonSolver::neighbours(int a, int b) const {
  return a == b || links_[link_of_node_[a]].parent == b || links_[link_of_node_[b]].parent == a;
}

bool TreeNewtonSolver::applicable() const {
  if (!sys_.frame_nodes_only()) return false;
  if (!sys_.cut_rows().empty() || !sys_.redundant_rows().empty()) return false;
  for (const auto& e : sys_.elements())
    for (int a : e->nodes())
      for (int b : e->nodes())
        if (!neighbours(a, b)) return false;
  return true;
}

std::optional<VecX> TreeNewtonSolver::solve(const VecX& qm, const VecX& q1, const VecX& u,
                                            const SpMat& K, const VecX& b) const {
  const int N = sys_.node_count();
  // 12 × 12 blocks of K̂: on the diagonal, and between each node and its parent (both ways).
  std::vector<Mat<12, 12>> Kd(N, Mat<12, 12>::Zero()), Kcp(N, Mat<12, 12>::Zero()),
      Kpc(N, Mat<12, 12>::Zero());
  std::vector<bool> coupled(N, false);  // K̂ has entries between the node and its parent
  for (int c = 0; c < K.outerSize(); ++c)
    for (SpMat::InnerIterator it(K, c); it; ++it) {
      const int r = static_cast<int>(it.row()), col = static_cast<int>(it.col());
      const int a = r / 12, bn = col / 12;
      if (!neighbours(a, bn)) return std::nullopt;
      if (a == bn)
        Kd[a](r % 12, col % 12) += it.value();
      else if (links_[link_of_node_[a]].parent == bn)
        Kcp[a](r % 12, col % 12) += it.value();
      else
        Kpc[bn](r % 12, col % 12) += it.value();
      if (a != bn) coupled[links_[link_of_node_[a]].parent == bn ? a : bn] = true;
    }

  std::vector<Mat<12, 6>> Pm(N), P1(N);
  for (int i = 0; i < N; ++i) {
    Pm[i] = fn::null_space(qm.segment<12>(12 * i));
    P1[i] = fn::null_space(q1.segment<12>(12 * i));
  }

  const int L = static_cast<int>(links_.size());
  std::vector<Mat6> Ahat(N), Chat(N), T(N), Am(N, Mat6::Zero());
  std::vector<Vec<6>> zhat(N, Vec<6>::Zero()), tau(N);
  std::vector<Blockr6> Gam(N);
  std::vector<Vecr> del(N);
  // Fixed-size 6 × 12 · 12 × 12 · 12 × 6 products (lazy: no temporaries through the GEMM path).
  auto project = [](const Mat<12, 6>& A, const Mat<12, 12>& K, const Mat<12, 6>& B) {
    const Mat<12, 6> KB = K.lazyProduct(B);
    return Mat6(A.transpose().lazyProduct(KB));
  };
  for (int i = 0; i < N; ++i) Ahat[i] = project(Pm[i], Kd[i], P1[i]);

  for (int l = L - 1; l >= 0; --l) {
    const Link& k = links_[l];
    const int g = k.node, p = k.parent;
    Mat6 A1 = Mat6::Zero();
    Block6r Bm, E;
    if (k.joint < 0) {
      Bm = Mat6::Identity();
      E = Mat6::Identity();
    } else {
      const auto& J = *sys_.joints()[k.joint].frame;
      const fn::Q qa_m = sys_.node_q(qm, p), qb_m = sys_.node_q(qm, g);
      const fn::Q qa_1 = sys_.node_q(q1, p), qb_1 = sys_.node_q(q1, g);
      Bm = J.freedom_block(qa_m, qb_m);
      E = J.freedom_block(qa_1, qb_1);
      if (p >= 0) {
        Am[g] = J.parent_block(qa_m, qb_m);
        A1 = J.parent_block(qa_1, qb_1);
      }
    }
    if (k.rotvec >= 0)
      E.middleCols<3>(k.rotvec) =
          E.middleCols<3>(k.rotvec) * rodrigues_tangent(u.segment<3>(k.nu_offset + k.rotvec));
    Chat[g] = p >= 0 && coupled[g] ? project(Pm[g], Kcp[g], P1[p]) : Mat6::Zero();

    const int r = k.freedoms;
    if (r > 0) {
      const Blockrr S = Bm.transpose() * Ahat[g] * E;
      const Eigen::PartialPivLU<Blockrr> lu(S);
      del[g] = lu.solve(Vecr(b.segment(k.nu_offset, r) - Bm.transpose() * zhat[g]));
      Gam[g] = -lu.solve(Blockr6(Bm.transpose() * (Ahat[g] * A1 + Chat[g])));
      if (!del[g].allFinite() || !Gam[g].allFinite())
        throw std::runtime_error("singular pivot block in the tree recursion");
      T[g] = A1 + E * Gam[g];
      tau[g] = E * del[g];
    } else {
      T[g] = A1;
      tau[g].setZero();
    }
    if (p >= 0) {
      const Mat6 Kpg = coupled[g] ? project(Pm[p], Kpc[g], P1[g]) : Mat6::Zero();
      Ahat[p] += Kpg * T[g] + Am[g].transpose() * (Ahat[g] * T[g] + Chat[g]);
      zhat[p] += Kpg * tau[g] + Am[g].transpose() * (Ahat[g] * tau[g] + zhat[g]);
    }
  }

  VecX du(u.size());
  std::vector<Vec<6>> t(N);
  for (const Link& k : links_) {
    const int g = k.node;
    const Vec<6> tp = k.parent >= 0 ? t[k.parent] : Vec<6>::Zero();
    t[g] = T[g] * tp + tau[g];
    if (k.freedoms > 0) du.segment(k.nu_offset, k.freedoms) = del[g] + Gam[g] * tp;
  }
  return du;
}

}  // namespace isoflex::system
