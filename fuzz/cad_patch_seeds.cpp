// Writes the seed corpus of the CAD-patch fuzzer (cad_patch_codec.hpp) into the folder given as
// the argument: the surfaces of the examples and of tests/data/cad as the built-in shapes make
// them (rectangle, cylinder sector = the quarter cylinder of the CAD test files, sphere sector,
// hemisphere, disc, and the closed cylinder, annulus and spherical cap), and an unclamped
// (periodic-like) patch as OCCT writes periodic surfaces, with the refinements the examples use.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numbers>

#include "cad_patch_codec.hpp"
#include "isoflex/geometry/builders.hpp"

namespace {

// A closed ring on the uniform knots −2 … 6 (degree 2 in u, domain [0, 4]): the knots of the
// periodic extension, as OCCT writes a periodic B-spline surface to STEP and IGES; linear in v.
isoflex::geometry::NurbsSurface unclamped_ring() {
  using namespace isoflex;
  geometry::NurbsSurface s;
  s.u = geometry::KnotVector(2, {-2, -1, 0, 1, 2, 3, 4, 5, 6});
  s.v = geometry::KnotVector(1, {0, 0, 1, 1});
  const double corner[6][2] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}, {1, 0}, {0, 1}};
  for (int j = 0; j < 2; ++j)
    for (const auto& c : corner) {
      s.points.emplace_back(c[0], c[1], j);
      s.weights.push_back(c[0] != 0 ? 1.0 : 0.75);
    }
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace isoflex;
  if (argc != 2) {
    std::cerr << "usage: cad_patch_seeds DIR\n";
    return 2;
  }
  const std::filesystem::path dir(argv[1]);
  std::filesystem::create_directories(dir);
  constexpr double pi = std::numbers::pi;
  const geometry::NurbsSurface shapes[] = {
      geometry::planar_rectangle(1, 0.5),
      geometry::cylinder_sector(1, 2, pi / 2),
      geometry::cylinder_sector(25, 50, 80 * pi / 180),
      geometry::sphere_sector(10, pi / 2, 0, pi / 2),
      geometry::sphere_sector(10, pi / 2, 0, 72 * pi / 180),
      geometry::hemisphere(10),
      geometry::disc(1),
      geometry::cylinder(1, 2),
      geometry::annulus(6, 10, 2 * pi),
      geometry::spherical_cap(10, 2 * pi / 3),
      unclamped_ring(),
  };
  int k = 0;
  for (const auto& s : shapes)
    for (const int refine : {0, 1, 2}) {
      std::ofstream(dir / ("seed_" + std::to_string(k++)), std::ios::binary) << fuzz::encode(
          s, static_cast<std::uint8_t>(refine == 2 ? 3 : 0), refine, refine, refine, refine);
    }
  std::cout << k << " seeds in " << dir.string() << "\n";
  return 0;
}
