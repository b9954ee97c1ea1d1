#include "isoflex/integrate/reduced_newton_matrix.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "isoflex/elements/beam_element.hpp"
#include "isoflex/math/frame_node.hpp"
#include "isoflex/math/rotation.hpp"

namespace isoflex::integrate {

namespace fn = frame_node;
using system::SpMat;

namespace {
constexpr int kOutside = -2;  // slot of an entry of 𝖦 outside its fixed pattern
}

bool ReducedNewtonMatrix::applicable(const system::System& sys) {
  // 12 × 12 node blocks: written for frame nodes.
  if (!sys.frame_nodes_only() || !sys.cut_rows().empty()) return false;
  std::vector<int> owners(sys.node_count(), 0);
  for (int r : sys.roots()) ++owners[r];
  for (int j : sys.tree_order()) ++owners[sys.joints()[j].child];
  return std::all_of(owners.begin(), owners.end(), [](int c) { return c == 1; });
}

ReducedNewtonMatrix::ReducedNewtonMatrix(const system::System& sys) : sys_(sys) {
  if (!applicable(sys))
    throw std::invalid_argument(
        "block assembly of the reduced Newton matrix needs a spanning forest without "
        "loop-closing rows");
  const int N = sys.node_count();
  const auto& joints = sys.joints();

  // ν-groups and the paths of the nodes (the nonzero blocks of E, (57)).
  path_.assign(N, {});
  parent_joint_.assign(N, -1);
  for (std::size_t r = 0; r < sys.roots().size(); ++r) {
    path_[sys.roots()[r]] = {static_cast<int>(groups_.size())};
    groups_.push_back({sys.root_nu_offsets()[r], 6, 3});
  }
  for (int j : sys.tree_order()) {
    const auto& J = joints[j];
    parent_joint_[J.child] = j;
    if (J.parent >= 0) path_[J.child] = path_[J.parent];
    if (J.frame->freedom_count() > 0) {
      path_[J.child].push_back(static_cast<int>(groups_.size()));
      groups_.push_back({J.nu_offset, J.frame->freedom_count(), J.frame->rotation_vector_offset()});
    }
  }

  // Node pairs coupled by K̂: the diagonal (masses of bodies, internal-constraint Hessians,
  // loads), element node pairs (mass, ∂f/∂q), joint parent/child pairs (joint Hessians).
  std::vector<std::pair<int, int>> pp;
  for (int i = 0; i < N; ++i) pp.push_back({i, i});
  for (const auto& e : sys.elements())
    for (int a : e->nodes())
      for (int b : e->nodes()) pp.push_back({a, b});
  for (const auto& J : joints)
    if (J.parent >= 0) {
      pp.push_back({J.parent, J.child});
      pp.push_back({J.child, J.parent});
    }
  std::sort(pp.begin(), pp.end());
  pp.erase(std::unique(pp.begin(), pp.end()), pp.end());
  row_pairs_.assign(N, {});
  for (const auto& [i, j] : pp) {
    row_pairs_[i].push_back({j, static_cast<int>(pairs_.size())});
    pairs_.push_back({i, j, 0});
  }

  // Blocks (g, h) of J: every combination of a group on the path of i and one on the path of j.
  std::map<std::pair<int, int>, int> block_of;
  for (Pair& p : pairs_) {
    p.first = static_cast<int>(pair_blocks_.size());
    for (int g : path_[p.i])
      for (int h : path_[p.j]) {
        const auto [it, inserted] = block_of.insert({{g, h}, static_cast<int>(block_of.size())});
        pair_blocks_.push_back(it->second);
      }
  }
  jblocks_.resize(block_of.size());
  system::Triplets t;
  for (const auto& [gh, k] : block_of) {
    jblocks_[k].g = gh.first;
    jblocks_[k].h = gh.second;
    const Group &G = groups_[gh.first], &H = groups_[gh.second];
    for (int c = 0; c < H.width; ++c)
      for (int r = 0; r < G.width; ++r) t.emplace_back(G.offset + r, H.offset + c, 1.0);
  }
  pattern_.resize(sys.k(), sys.k());
  pattern_.setFromTriplets(t.begin(), t.end());
  pattern_.makeCompressed();
  pattern_.coeffs().setZero();
  const int* outer = pattern_.outerIndexPtr();
  const int* inner = pattern_.innerIndexPtr();
  for (JBlock& b : jblocks_) {
    const Group &G = groups_[b.g], &H = groups_[b.h];
    b.first_slot = static_cast<int>(slots_.size());
    for (int c = 0; c < H.width; ++c) {
      const int col = H.offset + c;
      const int* s = std::lower_bound(inner + outer[col], inner + outer[col + 1], G.offset);
      slots_.push_back(static_cast<int>(s - inner));  // rows G.offset … + width: consecutive
    }
  }

  {
    std::vector<int> offset, width;
    for (const Group& G : groups_) {
      offset.push_back(G.offset);
      width.push_back(G.width);
    }
    std::vector<std::pair<int, int>> blocks;
    for (const JBlock& b : jblocks_) blocks.push_back({b.g, b.h});
    block_lu_ = BlockLU(offset, width, blocks);
    values_.assign(jblocks_.size(), BlockLU::Block6::Zero());  // BlockLU's zero padding
  }

  // Constant parts: element pairs and the mass blocks.
  for (const auto& e : sys.elements()) {
    beams_.push_back(dynamic_cast<const elements::BeamElement*>(e.get()));
    std::vector<int> ep;
    for (int a : e->nodes())
      for (int b : e->nodes()) ep.push_back(pair(a, b));
    element_pairs_.push_back(std::move(ep));
  }
  // Follower loads: each entry of the tangent's pattern → (pair, row, column) of a node block.
  for (const auto& L : sys.loads()) {
    std::vector<LoadEntry> entries;
    if (L->follower()) {
      const SpMat P = L->tangent_pattern(12 * static_cast<int>(L->nodes().size()));
      for (int c = 0; c < P.outerSize(); ++c)
        for (SpMat::InnerIterator it(P, c); it; ++it) {
          const int r = static_cast<int>(it.row());
          const int p = pair(L->nodes()[r / 12], L->nodes()[c / 12]);
          if (p < 0) throw std::logic_error("a load couples nodes outside the pattern of K");
          entries.push_back({p, r % 12, c % 12});
        }
    }
    load_entries_.push_back(std::move(entries));
  }
  mass_.assign(pairs_.size(), Block::Zero());
  const SpMat& M = sys.mass();
  for (int c = 0; c < M.outerSize(); ++c)
    for (SpMat::InnerIterator it(M, c); it; ++it) {
      const int p = pair(static_cast<int>(it.row()) / 12, static_cast<int>(it.col()) / 12);
      if (p < 0) throw std::logic_error("mass matrix couples nodes outside the pattern of K");
      mass_[p](it.row() % 12, it.col() % 12) += it.value();
    }
  selected_all_ = sys.selected_rows();
  for (int i = 0; i < N; ++i) diagonal_pair_.push_back(pair(i, i));
  {
    // M is symmetric as built (every element's mass is); checked entry by entry, bit for bit.
    const SpMat& M = sys.mass();
    const SpMat Mt = M.transpose();
    mass_symmetric_ =
        M.isCompressed() && Mt.nonZeros() == M.nonZeros() &&
        std::equal(M.outerIndexPtr(), M.outerIndexPtr() + M.outerSize() + 1, Mt.outerIndexPtr()) &&
        std::equal(M.innerIndexPtr(), M.innerIndexPtr() + M.nonZeros(), Mt.innerIndexPtr()) &&
        std::equal(M.valuePtr(), M.valuePtr() + M.nonZeros(), Mt.valuePtr());
  }

  // Pattern of 𝖦: the entries of the node and joint blocks that are nonzero at a generic
  // configuration (the Jacobians are linear in q, (22)), zero or not at the current one, so that
  // it is fixed. An entry outside it that turns out nonzero sends evaluate() to System::jacobian.
  {
    VecX qg = sys.q0();  // a deterministic generic perturbation (no global RNG state)
    for (int k = 0; k < sys.n(); ++k) qg(k) += 0.1 * std::sin(0.7 * k + 1.3);
    std::vector<Mat<6, 12>> Gn(N);
    for (int i = 0; i < N; ++i) Gn[i] = fn::jacobian(qg.segment<12>(12 * i));
    std::vector<MatX> Gj;
    for (const auto& J : joints)
      Gj.push_back(J.frame->jacobian(sys.node_q(qg, J.parent), sys.node_q(qg, J.child)));
    std::vector<int> sel(sys.m_all(), -1);
    for (std::size_t r = 0; r < selected_all_.size(); ++r) sel[selected_all_[r]] = r;
    system::Triplets tg;
    for (int i = 0; i < N; ++i)
      for (int c = 0; c < 12; ++c)
        for (int r = 0; r < 6; ++r)
          if (sel[6 * i + r] >= 0 && Gn[i](r, c) != 0.0)
            tg.emplace_back(sel[6 * i + r], 12 * i + c, 1.0);
    for (std::size_t j = 0; j < joints.size(); ++j) {
      const auto& J = joints[j];
      for (int c = 0; c < 24; ++c) {
        const int node = c < 12 ? J.parent : J.child;
        for (int r = 0; r < J.frame->constraint_count(); ++r)
          if (node >= 0 && sel[J.row_offset + r] >= 0 && Gj[j](r, c) != 0.0)
            tg.emplace_back(sel[J.row_offset + r], 12 * node + c % 12, 1.0);
      }
    }
    G_pattern_.resize(static_cast<int>(selected_all_.size()), sys.n());
    G_pattern_.setFromTriplets(tg.begin(), tg.end());
    G_pattern_.makeCompressed();
    G_pattern_.coeffs().setZero();
    const auto slot = [&](int row, int node, int c) {
      if (node < 0 || sel[row] < 0) return -1;  // not a selected entry: ignore
      const int col = 12 * node + c;
      const int* in = G_pattern_.innerIndexPtr();
      const int* o = G_pattern_.outerIndexPtr();
      const int* e = std::lower_bound(in + o[col], in + o[col + 1], sel[row]);
      return e != in + o[col + 1] && *e == sel[row] ? static_cast<int>(e - in) : kOutside;
    };
    for (int i = 0; i < N; ++i)
      for (int c = 0; c < 12; ++c)
        for (int r = 0; r < 6; ++r) node_slots_.push_back(slot(6 * i + r, i, c));
    for (const auto& J : joints) {
      joint_first_slot_.push_back(static_cast<int>(joint_slots_.size()));
      for (int c = 0; c < 24; ++c)
        for (int r = 0; r < J.frame->constraint_count(); ++r)
          joint_slots_.push_back(slot(J.row_offset + r, c < 12 ? J.parent : J.child, c % 12));
    }
    G_ = G_pattern_;
    // 𝖦𝖦ᵀ = Σ_columns c (column c)(column c)ᵀ: the products of entries sharing a column.
    system::Triplets ta;
    const int* o = G_pattern_.outerIndexPtr();
    const int* in = G_pattern_.innerIndexPtr();
    for (int c = 0; c < G_pattern_.outerSize(); ++c)
      for (int a = o[c]; a < o[c + 1]; ++a)
        for (int b = o[c]; b < o[c + 1]; ++b) ta.emplace_back(in[a], in[b], 1.0);
    SpMat full(G_pattern_.rows(), G_pattern_.rows());
    full.setFromTriplets(ta.begin(), ta.end());
    full.makeCompressed();
    // The ordering of FixedPatternLDLT (AMD on the pattern), and where each entry of the lower
    // triangle it reads lands in the upper triangle of the permuted matrix: entries marked by
    // their index, permuted as its factorization permutes them.
    {
      Eigen::SimplicialLDLT<SpMat, Eigen::Lower, Eigen::AMDOrdering<int>> amd;
      amd.analyzePattern(full);
      ggt_perm_ = amd.permutationP();
      ggt_perm_inv_ = amd.permutationPinv();
    }
    for (int k = 0; k < full.nonZeros(); ++k) full.valuePtr()[k] = k + 1.0;
    GGt_.resize(full.rows(), full.cols());
    GGt_.selfadjointView<Eigen::Upper>() =
        full.selfadjointView<Eigen::Lower>().twistedBy(ggt_perm_);
    GGt_.makeCompressed();
    std::vector<int> permuted_slot(full.nonZeros(), -1);  // entry of `full` → slot in GGt_
    for (int k = 0; k < GGt_.nonZeros(); ++k)
      permuted_slot[static_cast<int>(GGt_.valuePtr()[k]) - 1] = k;
    const int* ao = full.outerIndexPtr();
    const int* ai = full.innerIndexPtr();
    for (int c = 0; c < G_pattern_.outerSize(); ++c)
      for (int a = o[c]; a < o[c + 1]; ++a)
        for (int b = o[c]; b < o[c + 1]; ++b) {
          if (in[a] < in[b]) continue;  // the upper triangle, not read by the LDLᵀ
          const int col = in[b];
          const int* e = std::lower_bound(ai + ao[col], ai + ao[col + 1], in[a]);
          products_.push_back({a, b, permuted_slot[static_cast<std::size_t>(e - ai)]});
        }
    GGt_.coeffs().setZero();
    ldlt_.analyzePattern(GGt_);
  }
}

namespace {
// Pmᵀ K P1 for the internal null spaces P = [I 0; 0 −d̂₁; 0 −d̂₂; 0 −d̂₃] (31) of the directors
// dm (q_{n+½}) and d1 (q_{n+1}), by 3 × 3 blocks: only the rotation columns of P are not the
// identity, and with a row k and a column x, −k d̂ = (d × kᵀ)ᵀ and −d̂ᵀ x = d × x.
Mat<6, 6> project(const double* dm, const Mat<12, 12>& K, const double* d1) {
  // out += d × x in plain arithmetic (Eigen's cross on mapped 3-vectors cost 3.6 % more
  // instructions of the slider-crank's step).
  const auto cross_add = [](const double* d, const double* x, double* out) {
    out[0] += d[1] * x[2] - d[2] * x[1];
    out[1] += d[2] * x[0] - d[0] * x[2];
    out[2] += d[0] * x[1] - d[1] * x[0];
  };
  Mat<12, 3> KP;  // columns 3–5 of K P1, row by row
  for (int r = 0; r < 12; ++r) {
    double row[3] = {0.0, 0.0, 0.0};
    for (int I = 0; I < 3; ++I) {
      const double k[3] = {K(r, 3 + 3 * I), K(r, 4 + 3 * I), K(r, 5 + 3 * I)};
      cross_add(d1 + 3 * I, k, row);
    }
    KP.row(r) << row[0], row[1], row[2];
  }
  Mat<6, 6> out;
  out.topLeftCorner<3, 3>() = K.topLeftCorner<3, 3>();
  out.topRightCorner<3, 3>() = KP.topRows<3>();
  for (int c = 0; c < 6; ++c) {
    const double* x = c < 3 ? K.col(c).data() : KP.col(c - 3).data();
    double col[3] = {0.0, 0.0, 0.0};
    for (int I = 0; I < 3; ++I) cross_add(dm + 3 * I, x + 3 + 3 * I, col);
    out.block<3, 1>(3, c) << col[0], col[1], col[2];
  }
  return out;
}
}  // namespace

int ReducedNewtonMatrix::pair(int i, int j) const {
  const auto& row = row_pairs_[i];
  const auto it = std::lower_bound(row.begin(), row.end(), std::make_pair(j, -1));
  return it != row.end() && it->first == j ? it->second : -1;
}

void ReducedNewtonMatrix::twist_blocks(const VecX& q, std::vector<std::vector<Twist>>& E) const {
  // t_child = A t_parent + B τ (frame_joint.hpp): E_{c,g} = A E_{p,g}, E_{c,own} = B.
  E.resize(sys_.node_count());
  for (int r : sys_.roots()) E[r].assign(1, Twist::Identity(6, 6));
  for (int j : sys_.tree_order()) {
    const auto& J = sys_.joints()[j];
    const fn::Q qa = sys_.node_q(q, J.parent), qb = sys_.node_q(q, J.child);
    auto& out = E[J.child];
    out.clear();
    if (J.parent >= 0) {
      const Mat<6, 6> A = J.frame->parent_block(qa, qb);
      for (const Twist& B : E[J.parent]) out.push_back(A * B);
    }
    if (J.frame->freedom_count() > 0) out.push_back(J.frame->freedom_block(qa, qb));
  }
}

void ReducedNewtonMatrix::force(const VecX& qn, const VecX& q1, double dt, double t_mid,
                                bool want) const {
  const bool same_qn = qn.size() == force_qn_.size() && qn == force_qn_;
  if (!want && same_qn && dt == force_dt_ && t_mid == force_t_ && q1.size() == force_q1_.size() &&
      q1 == force_q1_)
    return;
  force_qn_ = qn;
  force_q1_ = q1;
  force_dt_ = dt;
  force_t_ = t_mid;
  // f = DV(qₙ, qₙ₊₁) − f_ext(q_{n+½}, t_{n+½}) as System::discrete_force, with the node blocks of
  // K̂ = (2/Δt) M + Δt ∂f/∂qₙ₊₁ (+ ½Δt Σ λ̂ᵢ Hᵢ in evaluate) added straight into the pattern.
  if (want) {
    K_.resize(pairs_.size());
    // (2/Δt) M of the pairs, kept while Δt is the same (the same products every iteration).
    if (scaled_mass_dt_ != dt) {
      scaled_mass_.resize(pairs_.size());
      for (std::size_t p = 0; p < pairs_.size(); ++p) scaled_mass_[p] = (2.0 / dt) * mass_[p];
      scaled_mass_dt_ = dt;
    }
    K_ = scaled_mass_;
  }
  VecX& f = f_;
  f.setZero(sys_.n());
  MatX& Ke = Ke_;
  const auto& elements = sys_.elements();
  // The beams' strains at qₙ, the same for every iteration of a step.
  if (!same_qn || beam_strains_n_.size() != elements.size()) {
    beam_strains_n_.resize(elements.size());
    for (std::size_t e = 0; e < elements.size(); ++e)
      if (beams_[e]) {
        const auto& nodes = elements[e]->nodes();
        elements::BeamElement::Q a;
        a << qn.segment<12>(12 * nodes[0]), qn.segment<12>(12 * nodes[1]);
        beam_strains_n_[e] = beams_[e]->raw_strains(a);
      }
  }
  for (std::size_t e = 0; e < elements.size(); ++e) {
    const auto& nodes = elements[e]->nodes();
    if (const elements::BeamElement* beam = beams_[e]) {
      // Two frame nodes: the fixed-size kernel, no heap allocation.
      using BQ = elements::BeamElement::Q;
      BQ a, b, dv;
      a << qn.segment<12>(12 * nodes[0]), qn.segment<12>(12 * nodes[1]);
      b << q1.segment<12>(12 * nodes[0]), q1.segment<12>(12 * nodes[1]);
      beam->discrete_gradient(a, b, dv, want ? &beam_K_ : nullptr, &beam_strains_n_[e]);
      for (int i = 0; i < 2; ++i) {
        f.segment<12>(12 * nodes[i]) += dv.segment<12>(12 * i);
        if (want)
          for (int j = 0; j < 2; ++j)
            K_[element_pairs_[e][i * 2 + j]] += dt * beam_K_.block<12, 12>(12 * i, 12 * j);
      }
      continue;
    }
    const int ne = static_cast<int>(nodes.size());
    VecX &a = a_, &b = b_;
    a.resize(12 * ne);
    b.resize(12 * ne);
    for (int i = 0; i < ne; ++i) {
      a.segment<12>(12 * i) = qn.segment<12>(12 * nodes[i]);
      b.segment<12>(12 * i) = q1.segment<12>(12 * nodes[i]);
    }
    VecX& dv = element_dv_;
    dv.setZero(12 * ne);
    elements[e]->add_discrete_gradient(a, b, dv, want ? &Ke : nullptr);
    for (int i = 0; i < ne; ++i) {
      f.segment<12>(12 * nodes[i]) += dv.segment<12>(12 * i);
      if (want)
        for (int j = 0; j < ne; ++j)
          K_[element_pairs_[e][i * ne + j]] += dt * Ke.block<12, 12>(12 * i, 12 * j);
    }
  }
  std::vector<double>& tangent = tangent_;
  for (std::size_t l = 0; l < sys_.loads().size(); ++l) {
    const loads::Load& L = *sys_.loads()[l];
    const std::vector<int>& nodes = L.nodes();
    VecX &x = a_, &g = b_;
    x.resize(12 * static_cast<int>(nodes.size()));
    for (std::size_t i = 0; i < nodes.size(); ++i)
      x.segment<12>(12 * i) = 0.5 * (qn.segment<12>(12 * nodes[i]) + q1.segment<12>(12 * nodes[i]));
    g.setZero(x.size());
    L.add_generalized_force(x, t_mid, g);
    for (std::size_t i = 0; i < nodes.size(); ++i)
      f.segment<12>(12 * nodes[i]) -= g.segment<12>(12 * i);
    if (!want || load_entries_[l].empty()) continue;
    tangent.assign(load_entries_[l].size(), 0.0);
    L.add_tangent(x, t_mid, -0.5 * dt, tangent.data());
    for (std::size_t k = 0; k < tangent.size(); ++k) {
      const LoadEntry& e = load_entries_[l][k];
      K_[e.pair](e.row, e.col) += tangent[k];
    }
  }
}

bool ReducedNewtonMatrix::midpoint_jacobian(const VecX& qm) const {
  double* gv = G_.valuePtr();
  bool outside = false;  // a nonzero outside the pattern of 𝖦
  const auto put = [&](int slot, double value) {
    if (slot >= 0)
      gv[slot] = value;
    else if (slot == kOutside && value != 0.0)
      outside = true;
  };
  for (int i = 0; i < sys_.node_count(); ++i) {
    const Mat<6, 12> Gi = fn::jacobian(qm.segment<12>(12 * i));
    const int* sl = &node_slots_[72 * i];
    for (int e = 0; e < 72; ++e) put(sl[e], Gi.data()[e]);  // column-major, as the slots
  }
  for (std::size_t j = 0; j < sys_.joints().size(); ++j) {
    const auto& J = sys_.joints()[j];
    const joints::FrameJoint::Rows Gj =
        J.frame->fixed_jacobian(fn::Q(sys_.node_q(qm, J.parent)), fn::Q(sys_.node_q(qm, J.child)));
    const int m = J.frame->constraint_count();
    const int* sl = &joint_slots_[joint_first_slot_[j]];
    for (int c = 0; c < 24; ++c)
      for (int r = 0; r < m; ++r) put(sl[m * c + r], Gj(r, c));
  }
  return !outside;
}

void ReducedNewtonMatrix::solve_normal(const VecX& rhs, VecX& lambda) const {
  double* av = GGt_.valuePtr();
  std::fill(av, av + GGt_.nonZeros(), 0.0);
  const double* gv = G_.valuePtr();
  for (const Product& p : products_) av[p.target] += gv[p.a] * gv[p.b];
  if (!ldlt_.factorize_ordered(GGt_)) throw std::runtime_error("matrix not positive definite");
  // Π rhs, the LDLᵀ solve, Πᵀ: SimplicialLDLT's own steps around its factor.
  const int m = static_cast<int>(rhs.size());
  permuted_.resize(m);
  for (int i = 0; i < m; ++i) permuted_(ggt_perm_.indices()(i)) = rhs(i);
  solved_.resize(m);
  ldlt_._solve_impl(permuted_, solved_);
  lambda.resize(m);
  for (int i = 0; i < m; ++i) lambda(ggt_perm_inv_.indices()(i)) = solved_(i);
}

bool ReducedNewtonMatrix::multipliers(const VecX& qn, const VecX& vn, const VecX& q1,
                                      const VecX& dq, double dt, double t_mid,
                                      solve::NormalEquations& normal, VecX& lambda,
                                      double& mismatch) const {
  if (!midpoint_jacobian(0.5 * (qn + q1))) return false;
  force(qn, q1, dt, t_mid, false);
  const VecX v1 = (2.0 / dt) * dq - vn;
  const VecX r = (1.0 / dt) * (sys_.mass() * (v1 - vn)) + f_;
  const VecX rhs = -(G_ * r);
  bool solved = false;
  try {
    solve_normal(rhs, lambda);
    solved = lambda.allFinite();
  } catch (const std::runtime_error&) {
  }
  if (!solved) lambda = normal.solve(G_, rhs);  // pivoted QR; throws where 𝖦 is rank deficient
  mismatch = (r + G_.transpose() * lambda).lpNorm<Eigen::Infinity>();
  return true;
}

const VecX& ReducedNewtonMatrix::evaluate(const VecX& qn, const VecX& vn, const VecX& u, double dt,
                                          double t_mid, solve::NormalEquations& normal, SpMat* Jout,
                                          const VecX* lambda_start) const {
  // Every vector is a kept workspace: an iteration allocates nothing.
  const int N = sys_.node_count();
  VecX &q1 = q1_, &qm = qm_, &v1 = v1_, &r0 = r0_;
  sys_.update(qn, u, q1, steps_, &dq_, &step_increments_);  // (14), (37)
  q1_qn_ = qn;
  q1_u_ = u;
  qm = 0.5 * (qn + q1);
  v1 = (2.0 / dt) * dq_ - vn;
  const bool want = Jout != nullptr;
  force(qn, q1, dt, t_mid, want);
  dv_ = v1 - vn;
  if (mass_symmetric_) {
    // Row i of M is its column i: r₀ᵢ = Σ_j M_ij dv_j over the column, j ascending, from zero —
    // the sums Eigen's column-major product accumulates in r₀ᵢ, in the same order (the same
    // roundings), without its scattered loads and stores of r₀ (−60 % of the product's
    // instructions, callgrind, slider-crank).
    const SpMat& M = sys_.mass();
    const int* outer = M.outerIndexPtr();
    const int* inner = M.innerIndexPtr();
    const double* value = M.valuePtr();
    const double* x = dv_.data();
    r0.resize(M.rows());
    double* out = r0.data();
    for (Eigen::Index i = 0; i < M.rows(); ++i) {
      double sum = 0.0;
      for (int k = outer[i]; k < outer[i + 1]; ++k) sum += value[k] * x[inner[k]];
      out[i] = sum;
    }
  } else {
    r0.noalias() = sys_.mass() * dv_;
  }
  r0 += dt * f_;
  sys_.reduce(qm, r0, R_, y_);  // 𝖯ᵀ r₀ by the leaves-to-root sweep
  if (!want) return R_;

  // λ̂ from r₀ ≈ −Δt 𝖦ᵀλ (least squares; energy_momentum.hpp) or the caller's, and ½Δt Σ λ̂ᵢ Hᵢ.
  VecX& lambda = lambda_;
  if (lambda_start && lambda_start->size() == static_cast<Eigen::Index>(selected_all_.size())) {
    lambda = *lambda_start;
  } else if (!midpoint_jacobian(qm)) {
    const SpMat Gm = sys_.jacobian(qm);
    lambda = normal.solve(Gm, -(Gm * r0) / dt);
  } else {
    rhs_.noalias() = G_ * r0;
    rhs_ = -rhs_ / dt;
    solve_normal(rhs_, lambda);
  }
  VecX& l = l_;
  l.setZero(sys_.m_all());
  for (std::size_t i = 0; i < selected_all_.size(); ++i) l(selected_all_[i]) = lambda(i);
  // ½Δt Σ λᵢ Hᵢ of the internal rows ½(d_I·d_J − δ_IJ) (31): λ_I I₃ on the director blocks (I, I),
  // λ_IJ I₃ on (I, J) and (J, I) — only the diagonals of these nine 3 × 3 blocks, added as
  // Eigen's K += ½Δt H adds them (the 117 zeros of H left out: K + ½Δt·0 is K). That sum is
  // contracted to a fused multiply-add where the target has one; here ½Δt λ would be computed
  // once for the three entries and added, so the fused form is written out where it is fast.
  const double half_dt = 0.5 * dt;
  for (int i = 0; i < N; ++i) {
    const Vec<6> li = l.segment<6>(6 * i);
    double* K = K_[diagonal_pair_[i]].data();
    const auto add = [&](int a, int b, double value) {  // director blocks a, b (0 … 2)
      for (int j = 0; j < 3; ++j) {
        double& k = K[12 * (3 + 3 * b + j) + 3 + 3 * a + j];
#ifdef FP_FAST_FMA
        k = std::fma(half_dt, value, k);
#else
        k += half_dt * value;
#endif
      }
    };
    for (int I = 0; I < 3; ++I) add(I, I, li(I));
    const int pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
    for (int k = 0; k < 3; ++k) {
      add(pairs[k][0], pairs[k][1], li(3 + k));
      add(pairs[k][1], pairs[k][0], li(3 + k));
    }
  }
  for (const auto& J : sys_.joints()) {
    const int m = J.frame->constraint_count();
    if (l.segment(J.row_offset, m).isZero(0.0)) continue;
    Mat<24, 24> H = Mat<24, 24>::Zero();
    J.frame->add_constraint_hessian(l.segment(J.row_offset, m), H);
    const int nodes[2] = {J.parent, J.child};
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b)
        if (nodes[a] >= 0 && nodes[b] >= 0)
          K_[pair(nodes[a], nodes[b])] += (0.5 * dt) * H.block<12, 12>(12 * a, 12 * b);
  }

  // E(q_{n+½}) and E(q_{n+1}) D(u).
  twist_blocks(qm, Em_);
  twist_blocks(q1, E1_);
  std::vector<Mat3>& T = T_;
  T.resize(groups_.size());
  for (std::size_t g = 0; g < groups_.size(); ++g)
    if (groups_[g].rotvec >= 0)
      T[g] = rodrigues_tangent(u.segment<3>(groups_[g].offset + groups_[g].rotvec));
  for (int i = 0; i < N; ++i) {
    if (frame_root(i)) continue;  // diag(I, T(θ)): taken as such below
    for (std::size_t b = 0; b < path_[i].size(); ++b) {
      const Group& G = groups_[path_[i][b]];
      if (G.rotvec >= 0)
        E1_[i][b].middleCols<3>(G.rotvec) = E1_[i][b].middleCols<3>(G.rotvec) * T[path_[i][b]];
    }
  }

  // J_{gh} = Σ_{(i,j)} E_{i,g}ᵀ K̃_{ij} E_{j,h} D_h, K̃_{ij} = P_int,iᵀ K̂_{ij} P_int,j.
  J_.resize(jblocks_.size());
  for (std::size_t k = 0; k < jblocks_.size(); ++k)
    J_[k].setZero(groups_[jblocks_[k].g].width, groups_[jblocks_[k].h].width);
  for (std::size_t p = 0; p < pairs_.size(); ++p) {
    const Pair& P = pairs_[p];
    const auto &pi = path_[P.i], &pj = path_[P.j];
    if (pi.empty() || pj.empty()) continue;
    const Mat<6, 6> Kt = project(qm.data() + 12 * P.i + 3, K_[p], q1.data() + 12 * P.j + 3);
    const int lj = static_cast<int>(pj.size());
    // A root's own block of E(q_{n+½}) is the identity: Iᵀ KE is KE exactly.
    const bool root = parent_joint_[P.i] < 0;
    if (frame_root(P.j)) {
      // E(q_{n+1}) D of a root frame node is diag(I, T(θ)) (37), so K̃ E D = [K̃ₗ K̃ᵣ T]: the
      // product's terms with the identity's ones and zeros are exact, and the lazy product sums
      // the others in the same order (pmul, then pmadd over the inner index), so these are the
      // 6 × 6 product's values at a sixth of its multiplications (beam nodes: most pairs).
      Mat<6, 6> KE;
      KE.leftCols<3>() = Kt.leftCols<3>();
      KE.rightCols<3>().noalias() = Kt.rightCols<3>().lazyProduct(T[pj[0]]);
      if (root) {
        Eigen::Map<Mat<6, 6>>(J_[pair_blocks_[P.first]].data()) += KE;
        continue;
      }
      const Twist KEt = KE;
      for (std::size_t a = 0; a < pi.size(); ++a)
        J_[pair_blocks_[P.first + static_cast<int>(a)]] += Em_[P.i][a].transpose().lazyProduct(KEt);
      continue;
    }
    for (int b = 0; b < lj; ++b) {
      const Twist& E = E1_[P.j][b];
      if (root && E.cols() == 6) {  // two root twists (beam nodes): fixed-size products
        using M6 = Mat<6, 6>;
        Eigen::Map<M6>(J_[pair_blocks_[P.first + b]].data()) +=
            Kt.lazyProduct(Eigen::Map<const M6>(E.data()));
        continue;
      }
      const Twist KE = Kt.lazyProduct(E);
      for (std::size_t a = 0; a < pi.size(); ++a) {
        Small& Jb = J_[pair_blocks_[P.first + static_cast<int>(a) * lj + b]];
        if (root)
          Jb += KE;
        else
          Jb += Em_[P.i][a].transpose().lazyProduct(KE);
      }
    }
  }

  // Values into the fixed pattern.
  SpMat& J = *Jout;
  const bool same =
      J.rows() == pattern_.rows() && J.cols() == pattern_.cols() && J.isCompressed() &&
      J.nonZeros() == pattern_.nonZeros() &&
      std::equal(pattern_.innerIndexPtr(), pattern_.innerIndexPtr() + pattern_.nonZeros(),
                 J.innerIndexPtr()) &&
      std::equal(pattern_.outerIndexPtr(), pattern_.outerIndexPtr() + pattern_.outerSize() + 1,
                 J.outerIndexPtr());
  if (!same) J = pattern_;
  double* values = J.valuePtr();
  for (std::size_t k = 0; k < jblocks_.size(); ++k) {
    const Small& B = J_[k];
    const int* slot = &slots_[jblocks_[k].first_slot];
    if (B.rows() == 6) {  // a column of a root's or a 6-freedom joint's rows: one fixed copy
      for (int c = 0; c < B.cols(); ++c)
        Eigen::Map<Vec<6>>(values + slot[c]) = Eigen::Map<const Vec<6>>(B.data() + 6 * c);
      continue;
    }
    for (int c = 0; c < B.cols(); ++c)
      for (int r = 0; r < B.rows(); ++r) values[slot[c] + r] = B(r, c);
  }
  return R_;
}

const VecX* ReducedNewtonMatrix::configuration(const VecX& qn, const VecX& u,
                                               VecX* increment) const {
  const bool same =
      qn.size() == q1_qn_.size() && u.size() == q1_u_.size() && qn == q1_qn_ && u == q1_u_;
  if (same && increment) *increment = dq_;
  return same ? &q1_ : nullptr;
}

const VecX& ReducedNewtonMatrix::solve(const SpMat& J, const VecX& b, bool refactorize) const {
  VecX& x = x_;
  // Kept factors were accepted by the residual of their first solve: the backward error of the
  // triangular solves (the growth of the elimination) does not depend on the right-hand side.
  const bool accepted = factorized_ && !refactorize;
  if (!accepted) {
    factorized_ = J.nonZeros() == pattern_.nonZeros() && J.isCompressed() && J.rows() == sys_.k();
    if (factorized_) {
      const double* v = J.valuePtr();
      // The blocks' corners; their padding stays zero (constructor).
      for (std::size_t k = 0; k < jblocks_.size(); ++k) {
        BlockLU::Block6& B = values_[k];
        const int rows = groups_[jblocks_[k].g].width, cols = groups_[jblocks_[k].h].width;
        const int* slot = &slots_[jblocks_[k].first_slot];
        if (rows == 6) {  // as in evaluate: a column in one fixed copy
          for (int c = 0; c < cols; ++c) B.col(c) = Eigen::Map<const Vec<6>>(v + slot[c]);
          continue;
        }
        for (int c = 0; c < cols; ++c)
          for (int r = 0; r < rows; ++r) B(r, c) = v[slot[c] + r];
      }
      factorized_ = block_lu_.factorize(values_);
      ++factorizations_;
    }
  }
  if (factorized_) {
    block_lu_.solve(b, x);
    if (x.allFinite()) {
      if (accepted) return x;
      // No pivoting across blocks: accept the factors by the residual.
      block_lu_.multiply(values_, x, check_);
      if ((check_ - b).lpNorm<Eigen::Infinity>() <= 1e-10 * b.lpNorm<Eigen::Infinity>()) return x;
    }
    factorized_ = false;
  }
  ++fallbacks_;
  x = lu_.solve(J, b);
  return x;
}

}  // namespace isoflex::integrate
