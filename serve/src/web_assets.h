#pragma once
// The page's files (serve/web), compiled into the binary by
// serve/embed_web.cmake so that the server reads no file to serve them.

#include <string_view>
#include <vector>

namespace tega::serve {

struct WebAsset {
  std::string_view name;          // file name in serve/web
  std::string_view content_type;
  std::string_view bytes;
};

const std::vector<WebAsset>& web_assets();

}  // namespace tega::serve
