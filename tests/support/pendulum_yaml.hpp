#pragma once
// The model file of a spherical pendulum (one body on a spherical joint to the ground) for the
// command-line tests, with the given solver entry and extra top-level lines (output, probes).
#include <string>

namespace isoflex::test {

inline std::string pendulum_yaml(const std::string& solver = "{dt: 0.01, t_end: 0.2}",
                                 const std::string& extra = "") {
  return "name: pendulum\n"
         "gravity: [0, 0, -9.81]\n"
         "solver: " +
         solver +
         "\n"
         "bodies:\n"
         "  - name: bob\n"
         "    mass: 1.0\n"
         "    inertia: [0.1, 0.1, 0.1]\n"
         "    position: [1, 0, 0]\n"
         "joints:\n"
         "  - {type: spherical, body_b: bob, point: [0, 0, 0]}\n" +
         extra;
}

}  // namespace isoflex::test
