#pragma once
// A square Kirchhoff–Love plate 1 × 1, t = 0.01, E = 10⁷, ν = 0.3, its edges held (`fixed:
// all`), under a uniform pressure growing with t, as one patch or cut into a grid of PU × PV
// patches joined by a coupling: the many-patch model of issue #17's bench
// (bench/kl_many_patch_bench.cpp) and of the tests of the couplings and their solvers.
#include <sstream>
#include <string>

namespace isoflex::test {

struct PlateGrid {
  int pu = 1, pv = 1;
  int elements = 6;  // per direction of the whole plate (a multiple of pu and pv)
  int degree = 2;
  std::string coupling;        // kl_interfaces.coupling, for pu · pv > 1
  std::string interface_keys;  // more keys of kl_interfaces, e.g. ", beta: 1000"
  std::string solver = "{analysis: static, dt: 1, t_end: 1}";
  bool centre_probe = false;           // a probe "centre" at (0.5, 0.5, 0)
  std::string support = "fixed: all";  // of every outer edge (e.g. "clamped: all")
};

inline std::string plate_grid_yaml(const PlateGrid& g) {
  std::ostringstream s;
  s.precision(17);
  s << "name: plate_grid\nsolver: " << g.solver << "\nsurfaces:\n";
  std::ostringstream shells, supports, loads;
  shells << "kl_shells:\n";
  supports << "kl_supports:\n";
  loads << "kl_loads:\n";
  const double wu = 1.0 / g.pu, wv = 1.0 / g.pv;
  const int eu = g.elements / g.pu, ev = g.elements / g.pv;
  for (int j = 0; j < g.pv; ++j)
    for (int i = 0; i < g.pu; ++i) {
      const std::string n = "p" + std::to_string(i) + "_" + std::to_string(j);
      s << "  - {name: " << n << ", builtin: {type: rectangle, size: [" << wu << ", " << wv
        << "], corner: [" << i * wu << ", " << j * wv << ", 0]}, refine: {elevate: ["
        << g.degree - 1 << ", " << g.degree - 1 << "], knots_per_span: [" << eu - 1 << ", "
        << ev - 1 << "]}}\n";
      shells << "  - {name: " << n << ", surface: " << n
             << ", material: {E: 1.0e7, nu: 0.3, thickness: 0.01}}\n";
      if (i == 0) supports << "  - {shell: " << n << ", edge: u0, " << g.support << "}\n";
      if (i == g.pu - 1) supports << "  - {shell: " << n << ", edge: u1, " << g.support << "}\n";
      if (j == 0) supports << "  - {shell: " << n << ", edge: v0, " << g.support << "}\n";
      if (j == g.pv - 1) supports << "  - {shell: " << n << ", edge: v1, " << g.support << "}\n";
      loads << "  - {shell: " << n << ", area_force: [0, 0, \"-1.0*t\"]}\n";
    }
  s << shells.str() << supports.str() << loads.str();
  if (g.centre_probe)
    s << "probes:\n  - {name: centre, shell: p" << g.pu / 2 << "_" << g.pv / 2
      << ", point: [0.5, 0.5, 0]}\n";
  if (g.pu * g.pv > 1) s << "kl_interfaces: {coupling: " << g.coupling << g.interface_keys << "}\n";
  return s.str();
}

}  // namespace isoflex::test
