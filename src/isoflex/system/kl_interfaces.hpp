#pragma once
// Interfaces between Kirchhoff–Love patches (IGA-thesis §4.4, Definition 4.1): boundary edges of
// two patches that coincide as curves. They are made conforming — the same degree and the same
// knots along the edge, by degree elevation and knot insertion (§4.2.2), which leave each surface
// unchanged — so that their control points coincide pairwise: the C⁰ joint (4.36c). Across each
// interface the triples of control points (the shared one and the next row on either side,
// Fig. 4.7) are the control net of a bending strip (§4.4.2) and of the continuity constraints of
// ch. 5. A patch is also an interface with itself, a == b, in two cases (docs/theory/multipatch.md
// §7): two of its own edges coincide (the seam of a closed patch, e.g. a full cylinder), or its
// basis is only C⁰ along an interior knot line (multiplicity = degree, the 90° joints of the
// circular built-ins) — one column of control points there, already shared, with a triple across
// it at each, so that the same couplings give the line its bending stiffness back instead of
// leaving a hinge inside the patch. docs/theory/multipatch.md.
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "isoflex/geometry/nurbs_surface.hpp"
#include "isoflex/loads/patch_edge.hpp"

namespace isoflex::system {

// What meets at an interface: two edges (of two patches, or of one closed patch), or the two
// sides of a C⁰ knot line inside one patch.
enum class KLInterfaceKind { edges, knot_line };

struct KLInterface {
  int a = -1, b = -1;  // patch indices, a < b for two patches, a == b for a seam or knot line
  loads::PatchEdge edge_a = loads::PatchEdge::u0, edge_b = loads::PatchEdge::u0;
  bool reversed = false;  // b's edge parameter runs against a's
  KLInterfaceKind kind = KLInterfaceKind::edges;
  // knot_line: the line ξ = knot (knot_along_v false) or η = knot (true) of patch a; edge_a and
  // edge_b are unused.
  bool knot_along_v = false;
  double knot = 0.0;
  // Triples left out because two of their points coincide (at a pole, where the edge rows of a
  // sphere's patch collapse): no angle there to keep, and AF-D's ratio c of (5.36) is 0/0.
  int degenerate_triples = 0;
  // One entry per triple, in the order of a's edge parameter: the control point on the interface
  // (in a's and in b's numbering) and the one in the next row of a and of b.
  std::vector<int> shared_a, shared_b, inner_a, inner_b;
  // The angle between the two patches at the triples, ∠(inner_a − shared, inner_b − shared) in
  // degrees: 180 where they continue smoothly, 90 at a right-angled kink.
  double angle_min = 0.0, angle_max = 0.0;
  int triples() const { return static_cast<int>(shared_a.size()); }
};

struct KLPatchJoining {
  // The surfaces, made conforming along every interface, with the coincident control points
  // moved to their mean (they differ by at most the tolerance).
  std::vector<geometry::NurbsSurface> surfaces;
  std::vector<KLInterface> interfaces;
  // What was changed to make interfaces conforming, one line each ("patch 1: 2 knots inserted
  // along η (edge u0, to match patch 0 edge u1)").
  std::vector<std::string> refinements;
  double tolerance = 0.0;  // absolute: two points closer than this coincide
  // For each patch and control point, the id of its group of coincident control points (equal
  // ids: one point of the joined shell, one node of the system).
  std::vector<std::vector<int>> point_group;
  // The seams left open at the model's request (KLJoinOptions::open_seam), one line each
  // ("\"ring\" edges u0 -- u1"), for `isoflex check`.
  std::vector<std::string> open_seams;
};

// Per patch, whether a seam (two of its own edges that coincide) stays open — the slit annulus
// of Sze et al. 2004; empty: every seam is joined.
struct KLJoinOptions {
  std::vector<bool> open_seam;
};

// A pair of edges that coincide but cannot be made conforming (different parametrizations of the
// same curve, or an edge that covers only part of the other).
struct KLInterfaceError : std::invalid_argument {
  KLInterfaceError(int a, int b, const std::string& what, std::string key_ = "")
      : std::invalid_argument(what), patch_a(a), patch_b(b), key(std::move(key_)) {}
  int patch_a, patch_b;
  std::string key;  // the key of patch_b's kl_shells entry at fault, "" for the entry
};

// Finds the interfaces among `surfaces`: edge pairs of different patches whose end points coincide
// within relative_tolerance × the diagonal of the bounding box of all control points and whose
// points coincide along the edge (checked by projection); pairs of edges of one patch that
// coincide point for point at equal parameters (a closed patch's seam, unless options leave it
// open); and every interior knot line of multiplicity = degree of a patch (after the
// conforming). Edges collapsed to a point are skipped. `names` (one per surface) name the
// patches in messages. Throws KLInterfaceError as above, for an interior knot of multiplicity >
// degree (the basis breaks there) and for an open seam asked of a patch that has none;
// std::invalid_argument for relative_tolerance ∉ (0, 0.01].
KLPatchJoining join_kl_patches(std::vector<geometry::NurbsSurface> surfaces,
                               double relative_tolerance, const std::vector<std::string>& names,
                               const KLJoinOptions& options = {});

}  // namespace isoflex::system
