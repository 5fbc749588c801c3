#pragma once
// A file name's extension in lower case ("OUT.VTS" → ".vts"): how every writer of the
// io library tells the format it is asked for.

#include <cctype>
#include <filesystem>
#include <string>

namespace interpatch::io::internal {

inline std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

}  // namespace interpatch::io::internal
