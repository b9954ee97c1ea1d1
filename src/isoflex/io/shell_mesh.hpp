#pragma once
// The deformed mid-surfaces of the Reissner–Mindlin director shells of one snapshot, as drawn in
// the VTK output (vtk_writer.hpp): one VTK_QUAD per shell element through its four nodes, in the
// element's node order (counter-clockwise seen from the directors' side), and nodal values for
// point data. Kept apart from the writer so that the mesh can be checked without parsing XML.
#include <vector>

#include "isoflex/integrate/snapshot.hpp"
#include "isoflex/io/vtk_writer.hpp"

namespace isoflex::io {

struct ShellMesh {
  // Every shell node used by an element is one point, in increasing node index (so a structured
  // shell's points keep its node numbering and neighbouring elements share their points, which
  // ParaView needs to draw one smooth surface and to interpolate point data). One cell per
  // element of Snapshot::shell_elements, in that order; velocities = φ̇, parts = kShellPart.
  BodyMesh mesh;
  std::vector<int> nodes;           // per point: its index into Snapshot::bodies
  std::vector<Vec3> displacements;  // per point: φ − φ of the reference snapshot
  std::vector<Vec3> directors;      // per point: the shell director d (column 2 of the pose)
};

// `reference_positions[i]` is φ of node i at the reference snapshot (t = 0 in a run). Throws
// std::runtime_error for an element node outside the snapshot's nodes or the reference.
ShellMesh shell_mesh(const integrate::Snapshot& s, const std::vector<Vec3>& reference_positions);

// The plane-stress von Mises formula applied to a symmetric 2×2 resultant tensor a in an
// orthonormal frame: √(a₁₁² + a₂₂² − a₁₁a₂₂ + 3a₁₂²), invariant under rotations of the frame.
// For the membrane forces n it is h·σ_vM of the membrane stress n/h; for the bending moments m,
// 6/h² times it is σ_vM of the bending stress at the faces ±h/2 (linear through the thickness).
// a₁₂ is the symmetric part ½(a₁₂ + a₂₁), the element's tensors being symmetric anyway.
double von_mises(const Eigen::Matrix2d& a);

}  // namespace isoflex::io
