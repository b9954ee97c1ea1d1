// ColouredElementLoop: every element once, no two elements sharing a control point at the same
// time, and per control point the same order of element visits for any number of threads.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include "isoflex/elements/coloured_element_loop.hpp"

using isoflex::elements::ColouredElementLoop;

namespace {

// A grid of nu × nv knot-span elements of degree (p, q) without repeated knots: element (iu, iv)
// has the control points (iu + a, iv + b), 0 ≤ a ≤ p, 0 ≤ b ≤ q, of a (nu + p) × (nv + q) net.
struct Grid {
  int nu, nv, p, q;
  int control_points() const { return (nu + p) * (nv + q); }
  template <class F>
  void for_each_point(int e, F&& f) const {
    const int iu = e % nu, iv = e / nu;
    for (int b = 0; b <= q; ++b)
      for (int a = 0; a <= p; ++a) f(iu + a + (nu + p) * (iv + b));
  }
};

// For every control point, the elements that touched it, in the order they did.
std::vector<std::vector<int>> visits(const Grid& g, const ColouredElementLoop& loop, int threads,
                                     std::atomic<int>* overlaps = nullptr) {
  std::vector<std::vector<int>> seen(static_cast<std::size_t>(g.control_points()));
  std::vector<std::atomic<int>> busy(seen.size());
  std::mutex mutex;
  loop.run(threads, [&](int e, int) {
    g.for_each_point(e, [&](int cp) {
      if (busy[cp]++ != 0 && overlaps) ++*overlaps;
    });
    {
      const std::lock_guard<std::mutex> lock(mutex);
      g.for_each_point(e, [&](int cp) { seen[cp].push_back(e); });
    }
    std::this_thread::sleep_for(std::chrono::microseconds(20));
    g.for_each_point(e, [&](int cp) { --busy[cp]; });
  });
  return seen;
}

}  // namespace

TEST(ColouredElementLoop, EveryElementOnceWithoutConflictsInAFixedOrder) {
  for (const Grid g :
       {Grid{13, 11, 2, 3}, Grid{20, 3, 4, 2}, Grid{1, 1, 2, 2}, Grid{7, 16, 5, 5}}) {
    const ColouredElementLoop loop(g.nu, g.nv, g.p, g.q);
    ASSERT_EQ(loop.elements(), g.nu * g.nv);
    std::vector<int> count(static_cast<std::size_t>(g.nu * g.nv), 0);
    loop.run(1, [&](int e, int worker) {
      EXPECT_EQ(worker, 0);
      ++count[static_cast<std::size_t>(e)];
    });
    for (int c : count) EXPECT_EQ(c, 1);

    const auto serial = visits(g, loop, 1);
    for (int threads : {2, 3, 4}) {
      std::atomic<int> overlaps{0};
      EXPECT_EQ(visits(g, loop, threads, &overlaps), serial)
          << g.nu << "x" << g.nv << " " << threads;
      EXPECT_EQ(overlaps.load(), 0) << g.nu << "x" << g.nv << " " << threads;
    }
  }
}

TEST(ColouredElementLoop, UsesTheThreadsAndRethrows) {
  const ColouredElementLoop loop(40, 40, 2, 2);  // 400 blocks, 100 per colour
  std::vector<std::atomic<int>> by_worker(4);
  loop.run(4, [&](int, int worker) {
    ASSERT_LT(worker, 4);
    ++by_worker[static_cast<std::size_t>(worker)];
    std::this_thread::sleep_for(std::chrono::microseconds(5));
  });
  int total = 0;
  for (auto& n : by_worker) total += n;
  EXPECT_EQ(total, 1600);
  EXPECT_GT(by_worker[1].load(), 0);

  for (int threads : {1, 3}) {
    std::atomic<int> calls{0};
    EXPECT_THROW(loop.run(threads,
                          [&](int e, int) {
                            ++calls;
                            if (e == 417) throw std::runtime_error("element 417");
                          }),
                 std::runtime_error);
    EXPECT_LT(calls.load(), 1600);
  }
  EXPECT_THROW(ColouredElementLoop(0, 3, 2, 2), std::invalid_argument);
  EXPECT_THROW(ColouredElementLoop(3, 3, 2, 0), std::invalid_argument);
}
