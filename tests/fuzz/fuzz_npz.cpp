// libFuzzer target: the bytes of an .npz archive -> io::parse_exact_npz (the code
// path of io::read_exact_npz and of {"npz": ...} in a spec). Bad input must end in
// interpatch::error; anything else crashes, and so does a form the reader accepts
// that contradicts itself.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>
#include <type_traits>
#include <variant>

#include "interpatch/error.hpp"
#include "interpatch/io/npz.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    const interpatch::io::ExactForm f = interpatch::io::parse_exact_npz(bytes, "fuzz.npz");
    // What the reader promises: a net of the size the knots need, all from the bytes
    // (a double of the net takes at least 4 bytes of the archive: float32).
    std::visit(
        [&](const auto& form) {
          std::size_t count = 1;
          if constexpr (std::is_same_v<std::decay_t<decltype(form)>, interpatch::BSplineSurface>) {
            count = static_cast<std::size_t>(form.knots_u().count()) * static_cast<std::size_t>(form.knots_v().count());
          } else {
            count = static_cast<std::size_t>(form.knots_u().count()) * static_cast<std::size_t>(form.knots_v().count()) *
                    static_cast<std::size_t>(form.knots_w().count());
          }
          if (form.control_points().size() != count || 3 * count * 4 > size) std::abort();
          if (form.rational() && form.weights().size() != count) std::abort();
        },
        f);
  } catch (const interpatch::error&) {
    // Bad input, reported as it should be.
  }
  return 0;
}
