// libFuzzer target: JSON text -> io::parse_json -> io::build -> a few evaluations.
// Bad input must end in interpatch::error; anything else (another exception, a
// sanitizer report, a hang) is a bug and crashes the run.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "interpatch/error.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/io/spec.hpp"

namespace {

using json = nlohmann::json;

// Inline points cost about 8 bytes of text each; 64 KiB of spec cannot ask for
// more than a few thousand, so each run stays in milliseconds. Larger grids are
// refused by build() before allocating (exit 5), which the CLI tests check.
constexpr std::size_t max_input = std::size_t{1} << 16;

// A file name a spec may reference: one of the small data files in
// tests/fuzz/data (plain names only), never a path the fuzzer invents, which
// could name a device or a huge file elsewhere on the machine.
bool allowed_file(const std::string& name) {
  if (name.empty() || name.front() == '.' || name.size() > 64) return false;
  for (const char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
                    c == '-' || c == '.';
    if (!ok) return false;
  }
  return true;
}

bool references_only_data_files(const json& j) {
  if (j.is_array()) {
    for (const json& e : j)
      if (!references_only_data_files(e)) return false;
  } else if (j.is_object()) {
    for (const auto& [key, value] : j.items()) {
      if ((key == "npy" || key == "csv") && value.is_string() && !allowed_file(value.get<std::string>())) return false;
      if (!references_only_data_files(value)) return false;
    }
  }
  return true;
}

void evaluate_a_little(const interpatch::io::Construction& c) {
  const std::vector<double> t = interpatch::linspace(0, 1, 3);
  if (interpatch::io::is_volume(c)) {
    const interpatch::Volume& v = interpatch::io::volume_evaluator(c);
    (void)v.evaluate(t, t, t);
    (void)v.derivatives(0.5, 0.5, 0.5);
  } else {
    const interpatch::Surface& s = interpatch::io::evaluator(c);
    (void)s.evaluate(t, t);
    (void)s.derivatives(0.5, 0.5);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > max_input) return -1;  // not kept in the corpus
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const json spec = interpatch::io::parse_json(text, "fuzz.json");
    if (!references_only_data_files(spec)) return -1;
    const interpatch::io::Construction c = interpatch::io::build(spec, INTERPATCH_FUZZ_DATA);
    evaluate_a_little(c);
  } catch (const interpatch::error&) {
    // Bad input, reported as it should be.
  }
  return 0;
}
