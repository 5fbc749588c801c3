#pragma once
// File names as the io library takes them: the extension in lower case ("OUT.VTS"
// → ".vts"), how every writer tells the format it is asked for; a path quoted in a
// message.

#include <cctype>
#include <filesystem>
#include <string>

namespace interpatch::io::internal {

inline std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

inline std::string quoted(const std::filesystem::path& p) { return "'" + p.string() + "'"; }

}  // namespace interpatch::io::internal
