#include "isoflex/loads/patch_edge.hpp"

#include <stdexcept>

namespace isoflex::loads {

std::string to_string(PatchEdge e) {
  switch (e) {
    case PatchEdge::u0:
      return "u0";
    case PatchEdge::u1:
      return "u1";
    case PatchEdge::v0:
      return "v0";
    case PatchEdge::v1:
      return "v1";
  }
  return "?";
}

std::vector<int> edge_control_points(const geometry::NurbsSurface& s, PatchEdge e, int row) {
  const int n_u = s.n_u(), n_v = s.n_v();
  const int rows = edge_runs_along_v(e) ? n_u : n_v;
  if (row < 0 || row >= rows)
    throw std::invalid_argument("edge_control_points: row " + std::to_string(row) +
                                " outside [0, " + std::to_string(rows) + ") for edge " +
                                to_string(e));
  std::vector<int> out;
  switch (e) {
    case PatchEdge::u0:
    case PatchEdge::u1: {
      const int i = e == PatchEdge::u0 ? row : n_u - 1 - row;
      for (int j = 0; j < n_v; ++j) out.push_back(s.index(i, j));
      break;
    }
    case PatchEdge::v0:
    case PatchEdge::v1: {
      const int j = e == PatchEdge::v0 ? row : n_v - 1 - row;
      for (int i = 0; i < n_u; ++i) out.push_back(s.index(i, j));
      break;
    }
  }
  return out;
}

double edge_parameter(const geometry::NurbsSurface& s, PatchEdge e) {
  switch (e) {
    case PatchEdge::u0:
      return s.u.front();
    case PatchEdge::u1:
      return s.u.back();
    case PatchEdge::v0:
      return s.v.front();
    case PatchEdge::v1:
      return s.v.back();
  }
  return 0.0;
}

PatchEdge patch_edge_from_string(const std::string& name) {
  if (name == "u0") return PatchEdge::u0;
  if (name == "u1") return PatchEdge::u1;
  if (name == "v0") return PatchEdge::v0;
  if (name == "v1") return PatchEdge::v1;
  throw std::invalid_argument("unknown patch edge \"" + name + "\" (valid: u0, u1, v0, v1)");
}

}  // namespace isoflex::loads
