// The page of `uphill serve`: HTML, CSS and JavaScript, embedded in the program (the sources are
// src/server/assets/*, turned into byte arrays by CMake at configure time), so the page works
// offline: no CDN, no file next to the binary. The plot is an SVG drawn by the page's own script.
#pragma once

#include <string_view>
#include <vector>

namespace uphill {

struct PageAsset {
  const char* path;          // URL path, e.g. "/app.js"
  const char* content_type;
  std::string_view content;
};

const std::vector<PageAsset>& PageAssets();

}  // namespace uphill
