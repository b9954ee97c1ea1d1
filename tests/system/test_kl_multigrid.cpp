// The transfer operators of geometric multigrid (system/kl_multigrid.hpp) on a rational patch
// (the Scordelis–Lo roof, a NURBS cylinder sector): every coarse function of every level is a
// function of the fine patch, exactly — the coarse field Σ N^c_i c_i / W evaluated directly equals
// the fine field Σ R_j x_j of the interpolated coefficients x = P_1 ⋯ P_l c.
#include <gtest/gtest.h>

#include <random>

#include "isoflex/geometry/knot_hierarchy.hpp"
#include "isoflex/geometry/nurbs_surface.hpp"
#include "isoflex/io/model_reader.hpp"
#include "isoflex/system/kl_multigrid.hpp"
#include "isoflex/system/system.hpp"
#include "support/geometry.hpp"

using namespace isoflex;
using geometry::KnotVector;
using SpMat = Eigen::SparseMatrix<double>;

namespace {

const char* kRoof = R"(
solver: {analysis: static, dt: 1, t_end: 1}
surfaces:
  - name: roof
    builtin: {type: cylinder_sector, radius: 25, length: 50, angle: 80}
    refine: {elevate: [1, 2], knots_per_span: [15, 13]}
kl_shells:
  - {name: roof, surface: roof, material: {E: 4.32e8, nu: 0, thickness: 0.25}}
bodies:
  - {name: lump, mass: 2, inertia: [1, 1, 1], position: [0, 0, -10]}
)";

}  // namespace

TEST(KLMultigrid, CoarseFunctionsAreFunctionsOfTheFinePatch) {
  const model::Model m = io::read_model_string(kRoof, "roof.yaml");
  const system::System sys = system::System::compile(m);
  ASSERT_EQ(sys.kl_patches().size(), 1u);
  const system::KLPatchInstance& P = sys.kl_patches()[0];
  const geometry::NurbsSurface& S = P.element->patch().reference();
  ASSERT_TRUE(S.is_rational());
  const std::vector<SpMat> transfers = system::kl_transfer_operators(sys, 0);
  ASSERT_GE(transfers.size(), 2u);
  EXPECT_EQ(transfers[0].rows(), sys.n());

  std::mt19937 g(3);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  KnotVector cu = S.u, cv = S.v;
  SpMat chain = transfers[0];  // fine coefficients from those of level l
  for (std::size_t l = 0; l < transfers.size(); ++l) {
    if (l > 0) chain = SpMat(chain * transfers[l]);
    if (const auto c = geometry::coarsen(cu)) cu = *c;
    if (const auto c = geometry::coarsen(cv)) cv = *c;
    // The body's 7 coordinates (its position and quaternion, first in q) pass through first.
    const int others = sys.n() - 3 * static_cast<int>(P.nodes.size());
    ASSERT_EQ(chain.cols(), others + 3 * cu.n_basis() * cv.n_basis()) << "level " << l + 1;
    VecX c(chain.cols());
    for (Eigen::Index i = 0; i < c.size(); ++i) c(i) = u01(g) - 0.5;
    const VecX x = chain * c;
    double worst = 0.0, size = 0.0;
    for (int k = 0; k < 50; ++k) {
      const double xi = u01(g), eta = u01(g);
      const geometry::SurfaceBasis B = geometry::surface_basis(S, xi, eta);
      Vec3 fine = Vec3::Zero();
      for (int a = 0; a < B.R.cols(); ++a)
        fine += B.R(0, a) *
                x.segment<3>(sys.q_offset(P.nodes[static_cast<std::size_t>(B.global_index(S, a))]));
      const VecX Nu = test::all_basis_functions(S.u, xi), Nv = test::all_basis_functions(S.v, eta);
      double W = 0.0;
      for (int j = 0; j < S.n_v(); ++j)
        for (int i = 0; i < S.n_u(); ++i) W += Nu(i) * Nv(j) * S.weights[S.index(i, j)];
      const VecX Cu = test::all_basis_functions(cu, xi), Cv = test::all_basis_functions(cv, eta);
      Vec3 coarse = Vec3::Zero();
      for (int j = 0; j < cv.n_basis(); ++j)
        for (int i = 0; i < cu.n_basis(); ++i)
          coarse += Cu(i) * Cv(j) / W * c.segment<3>(others + 3 * (i + cu.n_basis() * j));
      worst = std::max(worst, (fine - coarse).norm());
      size = std::max(size, coarse.norm());
    }
    EXPECT_LT(worst, 1e-13 * size) << "level " << l + 1;
    // The coordinates that are not control points are carried over unchanged.
    for (int i = 0; i < others; ++i) {
      const int fine_index = sys.q_offset(0) + i;
      EXPECT_DOUBLE_EQ(x(fine_index), c(i)) << "level " << l + 1 << ", coordinate " << i;
    }
  }
}

namespace {

// Patch k's own interpolation from its coarse control points at level `levels` (1: the first
// coarse level) to its fine ones, one coordinate: the product of the knot insertions (and with
// `degree_then_knots` first the degree transfer where the degree is above 2), divided by the fine
// weights (kl_multigrid.hpp).
MatX own_chain(const geometry::NurbsSurface& S, std::size_t levels,
               system::Coarsening coarsening = system::Coarsening::knots) {
  KnotVector fu = S.u, fv = S.v;
  MatX chain = MatX::Identity(S.n_u() * S.n_v(), S.n_u() * S.n_v());
  const bool by_degree =
      coarsening == system::Coarsening::degree_then_knots && (S.u.degree() > 2 || S.v.degree() > 2);
  const auto lower = [](const KnotVector& kv, bool degree) {
    if (degree) return kv.degree() > 2 ? *geometry::lower_degree(kv) : kv;
    return geometry::coarsen(kv).value_or(kv);
  };
  const auto transfer = [](const KnotVector& c, const KnotVector& f) {
    return MatX(c.degree() == f.degree() ? geometry::knot_insertion_matrix(c, f)
                                         : geometry::degree_transfer_matrix(c, f));
  };
  for (std::size_t l = 0; l < levels; ++l) {
    const KnotVector cu = lower(fu, by_degree && l == 0), cv = lower(fv, by_degree && l == 0);
    const MatX Au = transfer(cu, fu), Av = transfer(cv, fv);
    MatX A = MatX::Zero(Au.rows() * Av.rows(), Au.cols() * Av.cols());
    for (Eigen::Index j = 0; j < Av.rows(); ++j)
      for (Eigen::Index b = 0; b < Av.cols(); ++b)
        A.block(j * Au.rows(), b * Au.cols(), Au.rows(), Au.cols()) = Av(j, b) * Au;
    chain = chain * A;
    fu = cu;
    fv = cv;
  }
  for (Eigen::Index i = 0; i < chain.rows(); ++i)
    chain.row(i) /= S.weights[static_cast<std::size_t>(i)];
  return chain;
}

// Every coarse field of every level, interpolated to the fine level, is on each patch a coarse
// function of that patch (x_k = L_k z for some z, L_k the patch's own chain): where patches share
// control points (an interface, a seam) the coarse points on both sides are one, so that the fine
// field is continuous and in each patch's coarse space. Summing the rows of a shared point (or
// taking them from one side with the coarse points left apart) leaves the field outside.
void expect_coarse_fields_in_every_patch(
    const char* model, std::size_t patches,
    system::Coarsening coarsening = system::Coarsening::knots) {
  const model::Model m = io::read_model_string(model, "m.yaml");
  const system::System sys = system::System::compile(m);
  ASSERT_EQ(sys.kl_patches().size(), patches);
  const std::vector<SpMat> transfers = system::kl_transfer_operators(sys, 0, coarsening);
  ASSERT_GE(transfers.size(), 2u);
  std::mt19937 g(5);
  std::uniform_real_distribution<double> u01(-0.5, 0.5);
  SpMat chain = transfers[0];
  for (std::size_t l = 0; l < transfers.size(); ++l) {
    if (l > 0) chain = SpMat(chain * transfers[l]);
    VecX c(chain.cols());
    for (Eigen::Index i = 0; i < c.size(); ++i) c(i) = u01(g);
    const VecX x = chain * c;
    for (const system::KLPatchInstance& P : sys.kl_patches()) {
      const MatX L = own_chain(P.element->patch().reference(), l + 1, coarsening);
      const auto qr = L.colPivHouseholderQr();
      for (int d = 0; d < 3; ++d) {
        VecX xk(static_cast<Eigen::Index>(P.nodes.size()));
        for (std::size_t i = 0; i < P.nodes.size(); ++i)
          xk(static_cast<Eigen::Index>(i)) = x(sys.q_offset(P.nodes[i]) + d);
        const VecX z = qr.solve(xk);
        EXPECT_LT((L * z - xk).norm(), 1e-12 * xk.norm())
            << P.name << ", level " << l + 1 << ", coordinate " << d;
      }
    }
  }
}

// Two flat patches sharing the edge x ∈ [0, 10] at a right angle (examples/kl_l_shaped_plate).
const char* kL = R"(
solver: {analysis: static, dt: 1, t_end: 1, linear: true}
surfaces:
  - name: flange
    builtin: {type: rectangle, corner: [0, 0, 0], edge_u: [10, 0, 0], edge_v: [0, 1, 0]}
    refine: {elevate: [2, 2], knots_per_span: [15, 7]}
  - name: web
    builtin: {type: rectangle, corner: [0, 0, 0], edge_u: [10, 0, 0], edge_v: [0, 0, -3]}
    refine: {elevate: [2, 2], knots_per_span: [15, 9]}
kl_shells:
  - {name: flange, surface: flange, material: {E: 1.2e6, nu: 0, thickness: 0.1}}
  - {name: web, surface: web, material: {E: 1.2e6, nu: 0, thickness: 0.1}}
kl_interfaces: {coupling: c0}
)";

}  // namespace

TEST(KLMultigrid, CoarseFieldsAcrossAnInterfaceAreCoarseFunctionsOfBothPatches) {
  expect_coarse_fields_in_every_patch(kL, 2);
  // The shared edge's coarse points are counted once: 19 control points along it at the fine
  // level (3 + 16), 11 at the first coarse one (3 + 8).
  const system::System sys = system::System::compile(io::read_model_string(kL, "l.yaml"));
  const std::vector<SpMat> transfers = system::kl_transfer_operators(sys, 0);
  ASSERT_FALSE(transfers.empty());
  EXPECT_EQ(sys.n(), 3 * (19 * 11 + 19 * 13 - 19));
  EXPECT_EQ(transfers[0].cols(), 3 * (11 * 7 + 11 * 8 - 11));
}

TEST(KLMultigrid, CoarseFieldsAcrossASeamAreCoarseFunctionsOfThePatch) {
  // A closed annulus: its seam's control points are one node each (tests/system/test_kl_seams).
  expect_coarse_fields_in_every_patch(R"(
solver: {analysis: static, dt: 1, t_end: 1, linear: true}
surfaces:
  - name: ring
    builtin: {type: annulus, inner_radius: 6, outer_radius: 10, angle: 360}
    refine: {elevate: [0, 1], knots_per_span: [5, 3]}
kl_shells:
  - {name: ring, surface: ring, material: {E: 21.0e6, nu: 0, thickness: 0.03}}
)",
                                      1);
}

// p-multigrid's first level (Coarsening::degree_then_knots): degree 3 → 2 on the same knots, then
// fewer knots. The coarse points of the interface are one as at the other levels.
TEST(KLMultigrid, DegreeLevelAcrossAnInterfaceIsCoarseFunctionsOfBothPatches) {
  expect_coarse_fields_in_every_patch(kL, 2, system::Coarsening::degree_then_knots);
  const system::System sys = system::System::compile(io::read_model_string(kL, "l.yaml"));
  const std::vector<SpMat> transfers =
      system::kl_transfer_operators(sys, 0, system::Coarsening::degree_then_knots);
  ASSERT_GE(transfers.size(), 2u);
  // One control point fewer per direction and patch: 18 along the shared edge.
  EXPECT_EQ(transfers[0].cols(), 3 * (18 * 10 + 18 * 12 - 18));
}

// The lower-degree space of the roof is not inside the fine one, but its rigid motions are in the
// first coarse space exactly: the cylinder sector's geometry is one piece of degree 2 (in u,
// rational) and 1 (in v), and the transfer reproduces what both spaces hold (x = P₁ c solvable to
// round-off for a translation and a rotation of the control points). A random fine field is not.
TEST(KLMultigrid, DegreeLevelHoldsTheRigidMotionsOfTheRoof) {
  const model::Model m = io::read_model_string(kRoof, "roof.yaml");
  const system::System sys = system::System::compile(m);
  const std::vector<SpMat> transfers =
      system::kl_transfer_operators(sys, 0, system::Coarsening::degree_then_knots);
  ASSERT_GE(transfers.size(), 2u);
  const system::KLPatchInstance& P = sys.kl_patches()[0];
  const int others = sys.n() - 3 * static_cast<int>(P.nodes.size());
  EXPECT_EQ(transfers[0].cols(), others + 3 * 18 * 16);  // (16 + 2) × (14 + 2)
  const MatX P1 = MatX(transfers[0]);
  const auto qr = P1.colPivHouseholderQr();
  const auto residual = [&](const VecX& x) { return (P1 * qr.solve(x) - x).norm() / x.norm(); };
  const Vec3 t(0.3, -1.1, 0.7), w(0.2, 0.5, -0.4);
  VecX translation = VecX::Zero(sys.n()), rotation = VecX::Zero(sys.n()), random(sys.n());
  std::mt19937 g(7);
  std::uniform_real_distribution<double> u01(-0.5, 0.5);
  for (Eigen::Index i = 0; i < random.size(); ++i) random(i) = u01(g);
  for (int node : P.nodes) {
    translation.segment<3>(sys.q_offset(node)) = t;
    rotation.segment<3>(sys.q_offset(node)) =
        w.cross(Vec3(sys.q0().segment<3>(sys.q_offset(node))));
  }
  EXPECT_LT(residual(translation), 1e-12);
  EXPECT_LT(residual(rotation), 1e-12);
  EXPECT_GT(residual(random), 0.1);
}
