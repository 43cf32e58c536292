// Reading a metrics endpoint the way Prometheus does, for tests: one GET of
// /metrics and the value of one series from the text format. Header-only;
// tests link cpp-httplib themselves.
#ifndef MESHSEEK_COMMON_RPC_METRICS_SCRAPE_H_
#define MESHSEEK_COMMON_RPC_METRICS_SCRAPE_H_

#include <gtest/gtest.h>
#include <httplib.h>

#include <string>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"

namespace meshseek::rpc {

// The body of http://127.0.0.1:PORT/metrics; a failed test and "" when there
// is no answer or it is not 200.
inline std::string Scrape(int port) {
  httplib::Client client("127.0.0.1", port);
  httplib::Result result = client.Get("/metrics");
  EXPECT_TRUE(result) << "no answer from the metrics port " << port;
  if (!result) return "";
  EXPECT_EQ(result->status, 200);
  return result->body;
}

// The value of `series` (name{labels} exactly as served), -1 when absent,
// -2 when its value does not parse.
inline double SeriesValue(const std::string& text, const std::string& series) {
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    if (absl::ConsumePrefix(&line, series + " ")) {
      double value = 0;
      return absl::SimpleAtod(line, &value) ? value : -2;
    }
  }
  return -1;
}

}  // namespace meshseek::rpc

#endif  // MESHSEEK_COMMON_RPC_METRICS_SCRAPE_H_
