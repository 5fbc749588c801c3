#pragma once
// The files of the viewer page, embedded at build time (cmake/viewer.cmake): three.js
// as viewer/package-lock.json pins it, its OrbitControls, and viewer/src.

#include <span>
#include <string>
#include <string_view>

namespace interpatch::io::detail {

struct ViewerAssets {
  std::string three;           ///< three.module.min.js: the "three" module
  std::string orbit_controls;  ///< examples/jsm/controls/OrbitControls.js, which imports "three"
  std::string page;            ///< viewer/src/page.html, with its {{...}} slots
  std::string style;           ///< viewer/src/viewer.css
  std::string script;          ///< viewer/src/viewer.js, a module importing both
  std::string_view three_version;
};

/// The assets, joined from their pieces on first use.
const ViewerAssets& viewer_assets();

/// The pieces of one file (string literals), in order, as one string.
inline std::string joined(std::span<const char* const> pieces) {
  std::string s;
  for (const char* p : pieces) s += p;
  return s;
}

}  // namespace interpatch::io::detail
