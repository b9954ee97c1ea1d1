#pragma once
// The bytes of the CAD-patch fuzzer (cad_patch_fuzzer.cpp) as a parsed NURBS patch and back (the
// back direction writes the seed corpus, cad_patch_seeds.cpp). Little-endian, in this order:
//   u8  flags          bit 0 trimmed, bit 1 reversed orientation, bit 2 converted
//   i8  degree u, i8 degree v          (any value: negative and above kMaxDegree included)
//   u8  knot count u, u8 knot count v
//   f64 knots u …, f64 knots v …       (any bits: NaN, ±inf, decreasing)
//   u16 point count, f64 x y z …       (need not match the knot vectors)
//   u16 weight count, f64 weights …
//   u8  elevate u, v; u8 knots per span u, v   (refinement as a model file's `refine`, mod 4)
// Inputs cut short decode to nothing (the fuzzer then tries longer ones).
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "isoflex/geometry/nurbs_surface.hpp"

namespace isoflex::fuzz {

struct RawPatch {
  bool trimmed = false, reversed = false, converted = false;
  int degree_u = 0, degree_v = 0;
  std::vector<double> knots_u, knots_v;
  std::vector<Vec3> points;
  std::vector<double> weights;
  int elevate_u = 0, elevate_v = 0, knots_per_span_u = 0, knots_per_span_v = 0;
};

class ByteReader {
 public:
  ByteReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  template <class T>
  bool get(T& x) {
    if (size_ - at_ < sizeof(T)) return false;
    std::memcpy(&x, data_ + at_, sizeof(T));
    at_ += sizeof(T);
    return true;
  }
  bool doubles(std::size_t n, std::vector<double>& out) {
    if ((size_ - at_) / sizeof(double) < n) return false;
    out.resize(n);
    if (n > 0) std::memcpy(out.data(), data_ + at_, n * sizeof(double));
    at_ += n * sizeof(double);
    return true;
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t at_ = 0;
};

inline bool decode(const std::uint8_t* data, std::size_t size, RawPatch& p) {
  ByteReader r(data, size);
  std::uint8_t flags = 0, nu = 0, nv = 0, eu = 0, ev = 0, ku = 0, kv = 0;
  std::int8_t du = 0, dv = 0;
  std::uint16_t np = 0, nw = 0;
  std::vector<double> xyz;
  if (!r.get(flags) || !r.get(du) || !r.get(dv) || !r.get(nu) || !r.get(nv) ||
      !r.doubles(nu, p.knots_u) || !r.doubles(nv, p.knots_v) || !r.get(np) ||
      !r.doubles(3 * std::size_t{np}, xyz) || !r.get(nw) || !r.doubles(nw, p.weights) ||
      !r.get(eu) || !r.get(ev) || !r.get(ku) || !r.get(kv))
    return false;
  p.trimmed = flags & 1;
  p.reversed = flags & 2;
  p.converted = flags & 4;
  p.degree_u = du;
  p.degree_v = dv;
  p.points.clear();
  for (std::size_t k = 0; k < xyz.size(); k += 3)
    p.points.emplace_back(xyz[k], xyz[k + 1], xyz[k + 2]);
  p.elevate_u = eu % 4;
  p.elevate_v = ev % 4;
  p.knots_per_span_u = ku % 4;
  p.knots_per_span_v = kv % 4;
  return true;
}

inline std::string encode(const geometry::NurbsSurface& s, std::uint8_t flags, int elevate_u,
                          int elevate_v, int knots_u, int knots_v) {
  std::string out;
  const auto put = [&](const auto& x) { out.append(reinterpret_cast<const char*>(&x), sizeof(x)); };
  put(flags);
  put(static_cast<std::int8_t>(s.degree_u()));
  put(static_cast<std::int8_t>(s.degree_v()));
  put(static_cast<std::uint8_t>(s.u.knots().size()));
  put(static_cast<std::uint8_t>(s.v.knots().size()));
  for (double k : s.u.knots()) put(k);
  for (double k : s.v.knots()) put(k);
  put(static_cast<std::uint16_t>(s.points.size()));
  for (const Vec3& x : s.points) {
    put(x.x());
    put(x.y());
    put(x.z());
  }
  put(static_cast<std::uint16_t>(s.weights.size()));
  for (double w : s.weights) put(w);
  for (int v : {elevate_u, elevate_v, knots_u, knots_v}) put(static_cast<std::uint8_t>(v));
  return out;
}

}  // namespace isoflex::fuzz
