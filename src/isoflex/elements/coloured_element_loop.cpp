#include "isoflex/elements/coloured_element_loop.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

namespace isoflex::elements {

ColouredElementLoop::ColouredElementLoop(int nu, int nv, int bu, int bv) {
  if (nu < 1 || nv < 1 || bu < 1 || bv < 1)
    throw std::invalid_argument("ColouredElementLoop: grid " + std::to_string(nu) + " x " +
                                std::to_string(nv) + ", blocks " + std::to_string(bu) + " x " +
                                std::to_string(bv) + ": all must be >= 1");
  const int NI = (nu + bu - 1) / bu, NJ = (nv + bv - 1) / bv;
  order_.reserve(static_cast<std::size_t>(nu) * nv);
  block_start_.push_back(0);
  colour_start_.push_back(0);
  for (int colour = 0; colour < 4; ++colour) {
    for (int J = colour / 2; J < NJ; J += 2)
      for (int I = colour % 2; I < NI; I += 2) {
        for (int iv = J * bv; iv < std::min(nv, (J + 1) * bv); ++iv)
          for (int iu = I * bu; iu < std::min(nu, (I + 1) * bu); ++iu)
            order_.push_back(iu + nu * iv);
        block_start_.push_back(static_cast<int>(order_.size()));
      }
    colour_start_.push_back(blocks());
  }
}

void ColouredElementLoop::run(int threads, const std::function<void(int, int)>& f) const {
  const auto block = [&](int b, int worker) {
    for (int i = block_start_[b]; i < block_start_[b + 1]; ++i) f(order_[i], worker);
  };
  if (threads <= 1) {
    for (int b = 0; b < blocks(); ++b) block(b, 0);
    return;
  }
  std::exception_ptr error;
  std::mutex error_mutex;
  std::atomic<bool> failed{false};
  for (int c = 0; c < 4; ++c) {
    std::atomic<int> next{colour_start_[c]};
    const auto work = [&](int worker) {
      for (int b = next++; b < colour_start_[c + 1] && !failed; b = next++) {
        try {
          block(b, worker);
        } catch (...) {
          const std::lock_guard<std::mutex> lock(error_mutex);
          if (!error) error = std::current_exception();
          failed = true;
        }
      }
    };
    const int n_blocks = colour_start_[c + 1] - colour_start_[c];
    std::vector<std::jthread> pool;
    for (int w = 1; w < std::min(threads, n_blocks); ++w) {
      try {
        pool.emplace_back(work, w);
      } catch (const std::system_error&) {
        break;  // no more threads to be had: the ones running share the blocks, same results
      }
    }
    work(0);
    pool.clear();  // joins
    if (error) std::rethrow_exception(error);
  }
}

}  // namespace isoflex::elements
