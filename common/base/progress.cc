#include "common/base/progress.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>

#include "absl/strings/str_format.h"

namespace meshseek {

ProgressBar::ProgressBar(std::string label, std::size_t total, bool enabled)
    : label_(std::move(label)),
      total_(total),
      enabled_(enabled),
      tty_(isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

ProgressBar::~ProgressBar() { Finish(); }

std::string ProgressBar::FormatDuration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const long s = std::lround(seconds);
  if (s >= 3600) return absl::StrFormat("%d:%02d:%02d", s / 3600, (s / 60) % 60, s % 60);
  return absl::StrFormat("%d:%02d", s / 60, s % 60);
}

void ProgressBar::Advance(std::size_t n) {
  if (!enabled_) return;
  std::lock_guard<std::mutex> lock(mu_);
  done_ += n;
  const auto now = std::chrono::steady_clock::now();
  if (!advanced_) {
    advanced_ = true;
    rate_base_done_ = done_;
    rate_base_ = now;
  }
  if (tty_) {
    if (now - last_draw_ >= std::chrono::milliseconds(100) || done_ == total_) {
      last_draw_ = now;
      Draw(false);
    }
  } else {
    const int decile = total_ == 0 ? 10 : static_cast<int>(10 * done_ / total_);
    if (decile != last_decile_) {
      last_decile_ = decile;
      Draw(false);
    }
  }
}

void ProgressBar::Finish() {
  if (!enabled_) return;
  std::lock_guard<std::mutex> lock(mu_);
  if (finished_) return;
  finished_ = true;
  Draw(true);
}

void ProgressBar::Draw(bool final_line) {
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double since_base = std::chrono::duration<double>(now - rate_base_).count();
  // Items per second since the first Advance (0 until a second one); the
  // final line falls back to the whole run's when everything came at once.
  double rate = advanced_ && done_ > rate_base_done_ && since_base > 0
                    ? (done_ - rate_base_done_) / since_base
                    : 0.0;
  if (final_line && rate == 0.0 && elapsed > 0) rate = done_ / elapsed;
  std::string line;
  if (final_line) {
    line = absl::StrFormat(
        "%s: %d/%d done in %s (%.1f/s)", label_, done_, total_, FormatDuration(elapsed), rate);
  } else {
    constexpr int kWidth = 30;
    const double frac = total_ == 0 ? 1.0 : static_cast<double>(done_) / total_;
    const int filled = static_cast<int>(frac * kWidth);
    const double left = rate > 0 ? (total_ - done_) / rate : NAN;
    line = absl::StrFormat("%s [%s%s] %d/%d %.1f/s, %s left",
                           label_,
                           std::string(filled, '#'),
                           std::string(kWidth - filled, '.'),
                           done_,
                           total_,
                           rate,
                           FormatDuration(left));
  }
  if (tty_) {
    std::fprintf(stderr, "\r\033[K%s%s", line.c_str(), final_line ? "\n" : "");
  } else {
    std::fprintf(stderr, "%s\n", line.c_str());
  }
  std::fflush(stderr);
}

}  // namespace meshseek
