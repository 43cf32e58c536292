#include "common/base/parallel.h"

#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

namespace meshseek {

int ResolveThreadCount(int requested) {
  if (requested > 0) return requested;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw == 0 ? 1 : static_cast<int>(hw);
}

int CappedThreads(uint32_t asked, int num_threads) {
  return static_cast<int>(
      std::clamp<int64_t>(asked, 1, static_cast<int64_t>(ResolveThreadCount(num_threads))));
}

void ParallelFor(std::size_t n, int num_threads, const std::function<void(std::size_t)>& fn) {
  const std::size_t threads =
      std::min<std::size_t>(static_cast<std::size_t>(ResolveThreadCount(num_threads)), n);
  if (threads <= 1) {
    for (std::size_t i = 0; i < n; ++i) fn(i);
    return;
  }
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t i = next++; i < n; i = next++) fn(i);
  };
  std::vector<std::thread> pool;
  pool.reserve(threads - 1);
  for (std::size_t t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& th : pool) th.join();
}

}  // namespace meshseek
