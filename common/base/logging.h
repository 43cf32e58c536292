// Minimal leveled logging to stderr. Abseil 20220623 ships no absl/log, and the
// core must not depend on gRPC's logger, so this is the one logging entry point.
//
//   MESHSEEK_LOG(INFO) << "trained codebook with " << k << " words";
//
// Lines are written whole (one write per statement), so concurrent threads do
// not interleave inside a line. The minimum level comes from SetMinLogLevel()
// (default kInfo); kFatal aborts after writing.
#ifndef MESHSEEK_COMMON_BASE_LOGGING_H_
#define MESHSEEK_COMMON_BASE_LOGGING_H_

#include <sstream>

namespace meshseek {

enum class LogLevel { kDebug = 0, kInfo = 1, kWarning = 2, kError = 3, kFatal = 4 };

void SetMinLogLevel(LogLevel level);
LogLevel MinLogLevel();

namespace internal {

class LogMessage {
 public:
  LogMessage(LogLevel level, const char* file, int line);
  ~LogMessage();
  LogMessage(const LogMessage&) = delete;
  LogMessage& operator=(const LogMessage&) = delete;
  std::ostream& stream() { return stream_; }

 private:
  LogLevel level_;
  std::ostringstream stream_;
};

// Swallows a stream expression when the level is disabled.
struct LogVoidify {
  void operator&(std::ostream&) {}
};

}  // namespace internal
}  // namespace meshseek

#define MESHSEEK_LOG_LEVEL_DEBUG ::meshseek::LogLevel::kDebug
#define MESHSEEK_LOG_LEVEL_INFO ::meshseek::LogLevel::kInfo
#define MESHSEEK_LOG_LEVEL_WARNING ::meshseek::LogLevel::kWarning
#define MESHSEEK_LOG_LEVEL_ERROR ::meshseek::LogLevel::kError
#define MESHSEEK_LOG_LEVEL_FATAL ::meshseek::LogLevel::kFatal

#define MESHSEEK_LOG(severity)                                                                  \
  (MESHSEEK_LOG_LEVEL_##severity < ::meshseek::MinLogLevel())                                   \
      ? (void)0                                                                                 \
      : ::meshseek::internal::LogVoidify() &                                                    \
            ::meshseek::internal::LogMessage(MESHSEEK_LOG_LEVEL_##severity, __FILE__, __LINE__) \
                .stream()

#endif  // MESHSEEK_COMMON_BASE_LOGGING_H_
