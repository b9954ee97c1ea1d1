#pragma once
// A parallel loop over the elements of a tensor-product grid (knot-span elements of one NURBS
// patch) whose results do not depend on the number of threads. The grid of nu × nv elements
// (element e = iu + nu·iv) is cut into blocks of bu × bv elements, coloured in a 2 × 2 pattern:
// block (I, J) has colour (I mod 2) + 2 (J mod 2). Two blocks of one colour are at least one
// block apart in u or v, so with bu ≥ p and bv ≥ q (degrees) their elements share no control
// point and can scatter into the same global vector and matrix without locks. The colours run one
// after the other, the blocks of a colour are shared out among the threads, and inside a block the
// elements run in their natural order: every global entry receives its element contributions in
// the same order whatever the number of threads, so the sums agree bit for bit
// (docs/theory/kl-shell.md §6).
#include <functional>
#include <vector>

namespace isoflex::elements {

class ColouredElementLoop {
 public:
  ColouredElementLoop() = default;
  // Throws std::invalid_argument for nu, nv < 1 or bu, bv < 1.
  ColouredElementLoop(int nu, int nv, int bu, int bv);

  int elements() const { return static_cast<int>(order_.size()); }
  int blocks() const { return static_cast<int>(block_start_.size()) - 1; }

  // Calls f(e, worker) once for every element, 0 ≤ worker < threads, from `threads` threads (the
  // calling one among them; threads ≤ 1: all on the calling thread, same order). The first
  // exception thrown by f stops the loop after the running blocks and is rethrown here.
  void run(int threads, const std::function<void(int e, int worker)>& f) const;

 private:
  std::vector<int> order_;        // elements block by block, natural order inside a block
  std::vector<int> block_start_;  // block b: order_[block_start_[b], block_start_[b + 1])
  std::vector<int> colour_start_;  // colour c: blocks colour_start_[c] … colour_start_[c + 1] − 1
};

}  // namespace isoflex::elements
