// Data-parallel loops over independent work items on a fixed number of threads.
//
// meshseek parallelises across models (one model's extraction stays on one core),
// which keeps every per-model computation single-threaded and deterministic: the
// result never depends on the thread count or on scheduling.
#ifndef MESHSEEK_COMMON_BASE_PARALLEL_H_
#define MESHSEEK_COMMON_BASE_PARALLEL_H_

#include <cstddef>
#include <cstdint>
#include <functional>

namespace meshseek {

// Number of threads to use for a request of `requested` (<= 0 means "all cores").
int ResolveThreadCount(int requested);

// The threads one call that asks for `asked` may use on a server of
// `num_threads` (<= 0: all cores): at least 1, at most the server's.
int CappedThreads(uint32_t asked, int num_threads);

// Calls fn(i) for every i in [0, n), on up to `num_threads` threads (<= 0: all
// cores). Items are handed out one at a time from a shared counter, so uneven
// item costs balance out. Returns when every call has returned. `fn` must be
// safe to call concurrently for different i.
void ParallelFor(std::size_t n, int num_threads, const std::function<void(std::size_t)>& fn);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_BASE_PARALLEL_H_
