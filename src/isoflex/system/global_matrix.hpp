#pragma once
// A sparse matrix over the system's coordinates whose pattern is fixed when the system is compiled:
// the union of its contributors' patterns (elements, loads), and for each contributor a map from
// its local storage order to the global one. Assembling is then `values[map[k]] += local[k]` per
// contributor, with no triplets and no sorting per Newton iteration, and the sum over the
// contributors of an entry runs in the order they were added.
#include <Eigen/SparseCore>
#include <deque>
#include <vector>

#include "isoflex/math/types.hpp"

namespace isoflex::system {

class GlobalMatrix {
 public:
  using SpMat = Eigen::SparseMatrix<double>;

  GlobalMatrix() = default;
  // Not copied: the pattern's value array is never written (pattern()), and nothing copies a
  // System's matrices.
  GlobalMatrix(const GlobalMatrix&) = delete;
  GlobalMatrix& operator=(const GlobalMatrix&) = delete;
  // Moves swap the pattern: Eigen 3.4's SparseMatrix has no move constructor, and a copy of the
  // pattern would write its whole value array (a System is moved once, when it is compiled).
  GlobalMatrix(GlobalMatrix&& other) noexcept { swap(other); }
  GlobalMatrix& operator=(GlobalMatrix&& other) noexcept {
    swap(other);
    return *this;
  }

  // Registers a contributor with its local pattern over the global coordinates `coords` (local
  // row/column i is global coords[i]); returns its id. Before finalize(). `local` is swapped
  // in, not copied (Eigen 3.4's SparseMatrix has no move constructor; a patch's pattern is
  // 1.8 GB at 10⁶ unknowns).
  int add(SpMat local, std::vector<int> coords);
  // A dense contributor: every entry of the rows × columns block over coords.
  int add_dense(std::vector<int> coords);
  // Builds the n × n pattern and the maps, column by column from the contributors' columns (no
  // triplets: at 10⁶ unknowns they and Eigen's transposed copy were 4 GB beside the pattern).
  void finalize(int n);

  // The pattern: its structure only (its values are not set; reset() gives a matrix in it).
  const SpMat& pattern() const { return pattern_; }
  // Sets K to the pattern with zero values, keeping K's storage when it has the pattern already.
  void reset(SpMat& K) const;
  int local_entries(int id) const { return entries_[id]; }
  // Whether contributor id's pattern is the whole global pattern in the global storage order
  // (one NURBS patch alone in a model): its map is the identity and is not stored, and its
  // values may be written straight into K's storage.
  bool whole(int id) const { return entries_[id] > 0 && maps_[id].empty(); }
  // K.valuePtr()[map[k]] += local[k], K in the pattern (reset()).
  void scatter(int id, const double* local, SpMat& K) const;

 private:
  struct Contributor {
    SpMat local;  // empty for a dense one
    std::vector<int> coords;
  };
  void swap(GlobalMatrix& other) noexcept {
    parts_.swap(other.parts_);
    maps_.swap(other.maps_);
    entries_.swap(other.entries_);
    pattern_.swap(other.pattern_);
  }

  // A deque: adding a part never relocates the others, which would copy their patterns.
  std::deque<Contributor> parts_;
  std::vector<std::vector<int>> maps_;  // empty for a whole() contributor
  std::vector<int> entries_;
  SpMat pattern_;
};

}  // namespace isoflex::system
