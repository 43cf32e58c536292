// A progress bar for long loops: count, rate and time left, on stderr.
//
// On a terminal it redraws one line in place (at most ~10 times a second); when
// stderr is not a terminal (CI logs, pipes) it prints a plain line every 10 % so
// logs stay short. Advance() is thread-safe.
#ifndef MESHSEEK_COMMON_BASE_PROGRESS_H_
#define MESHSEEK_COMMON_BASE_PROGRESS_H_

#include <chrono>
#include <cstddef>
#include <mutex>
#include <string>

namespace meshseek {

class ProgressBar {
 public:
  // `enabled == false` makes every call a no-op (library callers and tests).
  ProgressBar(std::string label, std::size_t total, bool enabled = true);
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  void Advance(std::size_t n = 1);
  // Prints the final line (total and elapsed time). Called by the destructor if
  // not called before.
  void Finish();

  // "1:05", "0:07", "2:03:10".
  static std::string FormatDuration(double seconds);

 private:
  void Draw(bool final_line);

  std::string label_;
  std::size_t total_;
  bool enabled_;
  bool tty_;
  bool finished_ = false;
  std::size_t done_ = 0;
  // The rate counts from the first Advance on: a first jump (work found
  // already done, e.g. a resumed ingest) would otherwise read as millions
  // per second for the rest of the run.
  bool advanced_ = false;
  std::size_t rate_base_done_ = 0;
  std::chrono::steady_clock::time_point rate_base_;
  int last_decile_ = -1;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
  std::mutex mu_;
};

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_BASE_PROGRESS_H_
