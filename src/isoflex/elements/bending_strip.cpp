#include "isoflex/elements/bending_strip.hpp"

#include <stdexcept>
#include <string>

namespace isoflex::elements {

geometry::NurbsSurface bending_strip_surface(const std::vector<std::array<Vec3, 3>>& triples) {
  const int n = static_cast<int>(triples.size());
  if (n < 2)
    throw std::invalid_argument("bending strip: needs at least 2 triples of control points, got " +
                                std::to_string(n));
  geometry::NurbsSurface s;
  s.u = geometry::KnotVector(2, {0.0, 0.0, 0.0, 1.0, 1.0, 1.0});
  s.v = geometry::KnotVector::open_uniform(1, n - 1);
  for (const auto& t : triples)
    for (const Vec3& x : t) s.points.push_back(x);
  s.weights.assign(s.points.size(), 1.0);
  return s;
}

std::shared_ptr<KLShellPatch> bending_strip(const std::vector<std::array<Vec3, 3>>& triples,
                                            double young, double thickness) {
  KLShellSection strip{young, 0.0, thickness, 0.0, 0.0, true};
  return std::make_shared<KLShellPatch>(bending_strip_surface(triples), strip);
}

}  // namespace isoflex::elements
