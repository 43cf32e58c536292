// The web page's static files (web/), built into the binary by
// cmake/embed_web_assets.cmake: the gateway serves them with no files beside
// it and nothing fetched at run time.
#ifndef MESHSEEK_CLI_WEB_ASSETS_H_
#define MESHSEEK_CLI_WEB_ASSETS_H_

#include <string_view>

namespace meshseek::cli {

struct WebAsset {
  std::string_view path;  // "/index.html"
  const char* media_type;
  std::string_view content;
};

/// The asset served at `path`, or nullptr.
const WebAsset* FindWebAsset(std::string_view path);

}  // namespace meshseek::cli

#endif  // MESHSEEK_CLI_WEB_ASSETS_H_
