#include "common/features/local_features.h"

#include <algorithm>

#include "common/base/parallel.h"

namespace meshseek {

LocalFeatures DescribeInRuns(
    std::size_t n,
    int num_threads,
    const std::function<void(std::size_t begin, std::size_t end, LocalFeatures* out)>& describe) {
  const std::size_t runs =
      num_threads <= 1 || n <= 1 ? 1 : std::min(4 * static_cast<std::size_t>(num_threads), n);
  std::vector<LocalFeatures> parts(runs);
  ParallelFor(runs, num_threads, [&](std::size_t run) {
    describe(run * n / runs, (run + 1) * n / runs, &parts[run]);
  });
  for (std::size_t run = 1; run < parts.size(); ++run) AppendFeatures(parts[run], &parts[0]);
  return std::move(parts[0]);
}

}  // namespace meshseek
