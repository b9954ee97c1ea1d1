#include "isoflex/system/kl_boundary_conditions.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <utility>

#include "isoflex/geometry/quadrature.hpp"
#include "isoflex/system/row_selection.hpp"

namespace isoflex::system {

namespace {

const char* component_name(int k) {
  return k == 0 ? "x" : (k == 1 ? "y" : "z");
}

// One quadrature point on an edge: weight × |∂_θ c₀|, the reference point, the non-zero basis.
struct EdgePoint {
  double w = 0.0;
  Vec3 X = Vec3::Zero();
  std::vector<std::pair<int, double>> R;  // (control point, R_A)
};

std::vector<EdgePoint> edge_quadrature(const geometry::NurbsSurface& s, PatchEdge e, int n_points) {
  const bool along_v = loads::edge_runs_along_v(e);
  const geometry::KnotVector& kv = along_v ? s.v : s.u;
  const double fixed = loads::edge_parameter(s, e);
  const geometry::GaussRule rule =
      geometry::gauss_legendre(n_points > 0 ? n_points : kv.degree() + 2);
  std::vector<EdgePoint> out;
  for (const auto& el : geometry::span_elements(kv))
    for (const auto& qp : geometry::span_quadrature(el, rule)) {
      const double xi = along_v ? fixed : qp.xi, eta = along_v ? qp.xi : fixed;
      const geometry::SurfaceBasis B = geometry::surface_basis(s, xi, eta);
      EdgePoint p;
      Vec3 t = Vec3::Zero();
      for (int k = 0; k < static_cast<int>(B.R.cols()); ++k) {
        const int A = B.global_index(s, k);
        const Vec3& P = s.points[static_cast<std::size_t>(A)];
        p.X += B.R(0, k) * P;
        t += B.R(along_v ? 2 : 1, k) * P;
        if (B.R(0, k) != 0.0) p.R.emplace_back(A, B.R(0, k));
      }
      p.w = qp.weight * t.norm();
      out.push_back(std::move(p));
    }
  return out;
}

}  // namespace

KLBoundaryConditions::KLBoundaryConditions(geometry::NurbsSurface reference)
    : s_(std::move(reference)) {
  s_.validate();
}

KLBoundaryConditions& KLBoundaryConditions::fix_control_point(int cp, unsigned components) {
  if (cp < 0 || cp >= static_cast<int>(s_.points.size()))
    throw std::invalid_argument(fmt::format(
        "KLBoundaryConditions: control point {} outside [0, {})", cp, s_.points.size()));
  for (int k = 0; k < 3; ++k)
    if (components & (1u << k)) fixed_.push_back({3 * cp + k, {}});
  return *this;
}

KLBoundaryConditions& KLBoundaryConditions::fix_edge(PatchEdge e, unsigned components, int rows) {
  for (int r = 0; r < rows; ++r)
    for (int cp : loads::edge_control_points(s_, e, r)) fix_control_point(cp, components);
  return *this;
}

KLBoundaryConditions& KLBoundaryConditions::clamp_edge(PatchEdge e, unsigned components) {
  if (components != kCompXYZ) return fix_edge(e, components, 2);
  // The edge held, and the slope across it keeps its direction: t·(u_B − u_A) = 0 for t ⊥ the
  // reference slope direction X_B − X_A, the stretch across the edge free.
  fix_edge(e, kCompXYZ, 1);
  const std::vector<int> row0 = loads::edge_control_points(s_, e, 0);
  const std::vector<int> row1 = loads::edge_control_points(s_, e, 1);
  for (std::size_t i = 0; i < row0.size(); ++i) {
    const Vec3 d = (s_.points[static_cast<std::size_t>(row1[i])] -
                    s_.points[static_cast<std::size_t>(row0[i])])
                       .normalized();
    const Vec3 t1 = d.unitOrthogonal(), t2 = d.cross(t1);
    add_slope_rows(
        row0[i], row1[i], t1, t2,
        fmt::format("clamped {}: slope at control point {}", loads::to_string(e), row1[i]));
  }
  return *this;
}

void KLBoundaryConditions::add_slope_rows(int a, int b, const Vec3& t1, const Vec3& t2,
                                          const std::string& label) {
  for (const Vec3& t : {t1, t2}) {
    LinkRow r;
    for (int k = 0; k < 3; ++k)
      if (t(k) != 0.0) {
        r.entries.emplace_back(3 * b + k, t(k));
        r.entries.emplace_back(3 * a + k, -t(k));
      }
    r.label = label;
    link_rows_.push_back(std::move(r));
  }
}

KLBoundaryConditions& KLBoundaryConditions::symmetry_edge(PatchEdge e, const Vec3& n) {
  const double len = n.norm();
  if (!(len > 0.0) || !n.allFinite())
    throw std::invalid_argument("KLBoundaryConditions::symmetry_edge: the plane normal is zero");
  const Vec3 u = n / len;
  int axis = -1;
  for (int k = 0; k < 3; ++k)
    if (std::abs(u(k)) >= 1.0 - 1e-12) axis = k;
  const std::vector<int> row0 = loads::edge_control_points(s_, e, 0);
  const std::vector<int> row1 = loads::edge_control_points(s_, e, 1);
  const std::string edge = loads::to_string(e);
  if (axis >= 0) {
    for (int cp : row0) fix_control_point(cp, 1u << axis);
  } else {
    for (int cp : row0)
      link_rows_.push_back(
          {{{3 * cp, u.x()}, {3 * cp + 1, u.y()}, {3 * cp + 2, u.z()}},
           fmt::format("symmetry {}: normal displacement of control point {}", edge, cp)});
  }
  // An orthonormal basis (t₁, t₂) of the plane.
  const Vec3 t1 = u.unitOrthogonal(), t2 = u.cross(t1);
  for (std::size_t i = 0; i < row0.size(); ++i)
    add_slope_rows(
        row0[i], row1[i], t1, t2,
        fmt::format("symmetry {}: slope between control points {} and {}", edge, row0[i], row1[i]));
  return *this;
}

KLBoundaryConditions& KLBoundaryConditions::prescribe_control_point(
    int cp, int component, std::function<double(double)> u) {
  if (cp < 0 || cp >= static_cast<int>(s_.points.size()) || component < 0 || component > 2)
    throw std::invalid_argument(fmt::format(
        "KLBoundaryConditions: control point {} / component {} out of range", cp, component));
  fixed_.push_back({3 * cp + component, std::move(u)});
  return *this;
}

KLBoundaryConditions& KLBoundaryConditions::prescribe_edge(
    PatchEdge e, std::function<Vec3(double, const Vec3&)> u, unsigned components, int n_points) {
  if (!u) throw std::invalid_argument("KLBoundaryConditions::prescribe_edge: no function");
  weak_.push_back({e, std::move(u), components, n_points});
  return *this;
}

LinearConstraints KLBoundaryConditions::constraints() const {
  const int n = dofs();
  LinearConstraints out;
  // Later entries win (a prescribed value replaces a homogeneous one for the same dof).
  for (const Fixed& f : fixed_) out.eliminate(f.dof, f.value);
  std::vector<char> eliminated(static_cast<std::size_t>(n), 0);
  for (int d : out.eliminated) eliminated[static_cast<std::size_t>(d)] = 1;

  std::vector<Eigen::Triplet<double>> trip;
  int m = 0;
  // Symmetry rows (rhs 0) on the free dofs; entries on eliminated dofs drop out, which needs
  // their prescribed value to be 0.
  for (const LinkRow& r : link_rows_)
    for (const auto& [dof, c] : r.entries)
      for (const Fixed& f : fixed_)
        if (f.dof == dof && f.value)
          throw std::invalid_argument(
              fmt::format("KLBoundaryConditions: {} meets the prescribed displacement of dof {}",
                          r.label, dof));
  // A row left with one free entry, c·(x_i − X_i) = 0, is an elimination (which keeps the
  // Newton matrix symmetric positive definite); that can leave other rows with one entry.
  std::vector<LinkRow> link;
  for (bool changed = true; changed;) {
    changed = false;
    link.clear();
    for (const LinkRow& r : link_rows_) {
      LinkRow kept{{}, r.label};
      for (const auto& [dof, c] : r.entries)
        if (!eliminated[static_cast<std::size_t>(dof)]) kept.entries.emplace_back(dof, c);
      if (kept.entries.size() == 1) {
        eliminated[static_cast<std::size_t>(kept.entries[0].first)] = 1;
        out.eliminate(kept.entries[0].first);
        changed = true;
      } else if (!kept.entries.empty()) {
        link.push_back(std::move(kept));
      }
    }
  }
  if (!link.empty()) {
    // Independent rows, block by block (row_selection.hpp): rows that share no coordinate are
    // independent of each other.
    std::vector<Eigen::Triplet<double>> entries;
    for (std::size_t i = 0; i < link.size(); ++i)
      for (const auto& [dof, c] : link[i].entries)
        entries.emplace_back(static_cast<int>(i), dof, c);
    Eigen::SparseMatrix<double> D(static_cast<Eigen::Index>(link.size()), n);
    D.setFromTriplets(entries.begin(), entries.end());
    for (int i : independent_rows_by_blocks(D, 1e-10, false).rows) {
      for (const auto& [dof, c] : link[static_cast<std::size_t>(i)].entries)
        trip.emplace_back(m, dof, c);
      out.row_labels.push_back(link[static_cast<std::size_t>(i)].label);
      ++m;
    }
  }
  const int m_plane = m;
  out.homogeneous.assign(static_cast<std::size_t>(m_plane), true);  // d = 0 (below)

  // Weak edges: row (edge, function j, component k) = Σ_q w_q R_j R_A (x_{A,k} − X_{A,k}).
  struct WeakRow {
    int edge;  // index into weak_
    int cp;
    int k;
  };
  auto rows = std::make_shared<std::vector<WeakRow>>();
  auto points = std::make_shared<std::vector<std::vector<EdgePoint>>>();
  std::vector<char> owned(static_cast<std::size_t>(n), 0);
  for (std::size_t w = 0; w < weak_.size(); ++w) {
    const WeakEdge& we = weak_[w];
    points->push_back(edge_quadrature(s_, we.edge, we.n_points));
    const std::vector<EdgePoint>& pts = points->back();
    for (int k = 0; k < 3; ++k) {
      if (!(we.components & (1u << k))) continue;
      for (int j : loads::edge_control_points(s_, we.edge, 0)) {
        const auto dof = static_cast<std::size_t>(3 * j + k);
        if (eliminated[dof] || owned[dof]) continue;  // removed from Q_h, (4.26)
        owned[dof] = 1;
        // Row: ∫ R_j R_A ν dθ over the edge.
        std::vector<std::pair<int, double>> row;
        for (const EdgePoint& p : pts) {
          double Rj = 0.0;
          for (const auto& [A, R] : p.R)
            if (A == j) Rj = R;
          if (Rj == 0.0) continue;
          for (const auto& [A, R] : p.R) row.emplace_back(3 * A + k, p.w * Rj * R);
        }
        for (const auto& [col, v] : row) trip.emplace_back(m, col, v);
        rows->push_back({static_cast<int>(w), j, k});
        out.row_labels.push_back(fmt::format("prescribed edge {} {} function of control point {}",
                                             loads::to_string(we.edge), component_name(k), j));
        ++m;
      }
    }
  }
  out.C.resize(m, n);
  out.C.setFromTriplets(trip.begin(), trip.end());
  out.C.makeCompressed();
  if (!rows->empty()) {
    // d(t)_row = ∫ R_j ū_k(t, X) ν dθ; the plane rows have d = 0.
    auto edges = std::make_shared<std::vector<WeakEdge>>(weak_);
    out.rhs = [rows, points, edges, m, m_plane](double t) {
      VecX d = VecX::Zero(m);
      // ū at every quadrature point once per call.
      std::vector<std::vector<Vec3>> ubar(edges->size());
      for (std::size_t w = 0; w < edges->size(); ++w)
        for (const EdgePoint& p : (*points)[w]) ubar[w].push_back((*edges)[w].u(t, p.X));
      for (std::size_t r = 0; r < rows->size(); ++r) {
        const WeakRow& wr = (*rows)[r];
        const auto& pts = (*points)[static_cast<std::size_t>(wr.edge)];
        double acc = 0.0;
        for (std::size_t q = 0; q < pts.size(); ++q)
          for (const auto& [A, R] : pts[q].R)
            if (A == wr.cp) acc += pts[q].w * R * ubar[static_cast<std::size_t>(wr.edge)][q](wr.k);
        d(m_plane + static_cast<int>(r)) = acc;
      }
      return d;
    };
  }
  return out;
}

}  // namespace isoflex::system
