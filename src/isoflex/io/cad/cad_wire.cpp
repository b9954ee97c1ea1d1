#include "isoflex/io/cad/cad_wire.hpp"

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <type_traits>
#include <vector>

namespace isoflex::io::detail {

namespace {

class Writer {
 public:
  template <class T>
  void value(const T& x) {
    static_assert(std::is_trivially_copyable_v<T>);
    out_.append(reinterpret_cast<const char*>(&x), sizeof(T));
  }
  void text(const std::string& s) {
    value<std::uint64_t>(s.size());
    out_ += s;
  }
  template <class T>
  void values(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    value<std::uint64_t>(v.size());
    out_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  std::string take() { return std::move(out_); }

 private:
  std::string out_;
};

class Reader {
 public:
  explicit Reader(std::string_view in) : in_(in) {}
  template <class T>
  T value() {
    T x;
    std::memcpy(&x, take(sizeof(T)), sizeof(T));
    return x;
  }
  std::string text() {
    const auto n = count(1);
    return std::string(take(n), n);
  }
  template <class T>
  std::vector<T> values() {
    const auto n = count(sizeof(T));
    std::vector<T> v(n);
    if (n > 0) std::memcpy(v.data(), take(n * sizeof(T)), n * sizeof(T));
    return v;
  }
  bool done() const { return at_ == in_.size(); }

 private:
  // A length read from the bytes, checked against what is left before anything is allocated.
  std::size_t count(std::size_t item_size) {
    const auto n = value<std::uint64_t>();
    if (n > (in_.size() - at_) / item_size) throw std::runtime_error("CAD model bytes cut short");
    return static_cast<std::size_t>(n);
  }
  const char* take(std::size_t n) {
    if (n > in_.size() - at_) throw std::runtime_error("CAD model bytes cut short");
    const char* p = in_.data() + at_;
    at_ += n;
    return p;
  }
  std::string_view in_;
  std::size_t at_ = 0;
};

void put(Writer& w, const geometry::KnotVector& k) {
  w.value<std::int32_t>(k.degree());
  w.values(k.knots());
}

geometry::KnotVector get_knots(Reader& r) {
  const int degree = r.value<std::int32_t>();
  return geometry::KnotVector(degree, r.values<double>());
}

// Eigen vectors are not trivially copyable: as x, y, z each.
void put(Writer& w, const std::vector<Vec3>& points) {
  std::vector<double> xyz;
  xyz.reserve(3 * points.size());
  for (const Vec3& x : points) xyz.insert(xyz.end(), {x.x(), x.y(), x.z()});
  w.values(xyz);
}

std::vector<Vec3> get_points(Reader& r) {
  const std::vector<double> xyz = r.values<double>();
  if (xyz.size() % 3 != 0) throw std::runtime_error("CAD model bytes: points not in threes");
  std::vector<Vec3> points;
  points.reserve(xyz.size() / 3);
  for (std::size_t k = 0; k < xyz.size(); k += 3)
    points.emplace_back(xyz[k], xyz[k + 1], xyz[k + 2]);
  return points;
}

}  // namespace

std::string to_bytes(const CadModel& model) {
  Writer w;
  w.text(model.file.string());
  w.value<std::int32_t>(static_cast<std::int32_t>(model.format));
  w.text(model.length_unit);
  w.value<std::uint64_t>(model.patches.size());
  for (const CadPatch& p : model.patches) {
    w.text(p.name);
    w.value<std::int32_t>(p.index);
    put(w, p.surface.u);
    put(w, p.surface.v);
    put(w, p.surface.points);
    w.values(p.surface.weights);
    w.value<std::uint8_t>(p.trimmed);
    w.value<std::uint8_t>(p.reversed_orientation);
    w.value<std::uint8_t>(p.converted);
    w.text(p.surface_type);
    w.text(p.entity);
  }
  return w.take();
}

CadModel model_from_bytes(std::string_view bytes) {
  Reader r(bytes);
  CadModel model;
  model.file = r.text();
  model.format = static_cast<CadFormat>(r.value<std::int32_t>());
  model.length_unit = r.text();
  const auto n = r.value<std::uint64_t>();
  for (std::uint64_t k = 0; k < n; ++k) {
    CadPatch p;
    p.name = r.text();
    p.index = r.value<std::int32_t>();
    p.surface.u = get_knots(r);
    p.surface.v = get_knots(r);
    p.surface.points = get_points(r);
    p.surface.weights = r.values<double>();
    p.trimmed = r.value<std::uint8_t>() != 0;
    p.reversed_orientation = r.value<std::uint8_t>() != 0;
    p.converted = r.value<std::uint8_t>() != 0;
    p.surface_type = r.text();
    p.entity = r.text();
    model.patches.push_back(std::move(p));
  }
  if (!r.done()) throw std::runtime_error("CAD model bytes have trailing data");
  return model;
}

std::string strings_to_bytes(const std::vector<std::string>& strings) {
  Writer w;
  w.value<std::uint64_t>(strings.size());
  for (const auto& s : strings) w.text(s);
  return w.take();
}

std::vector<std::string> strings_from_bytes(std::string_view bytes) {
  Reader r(bytes);
  const auto n = r.value<std::uint64_t>();
  std::vector<std::string> out;
  for (std::uint64_t k = 0; k < n; ++k) out.push_back(r.text());
  if (!r.done()) throw std::runtime_error("CAD error bytes have trailing data");
  return out;
}

}  // namespace isoflex::io::detail
