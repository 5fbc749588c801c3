// libFuzzer target: the bytes of a .npy file -> io::parse_npy (the code path of
// io::read_npy). Bad input must end in interpatch::error; anything else crashes.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "interpatch/error.hpp"
#include "interpatch/io/npy.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    const interpatch::io::NpyArray a = interpatch::io::parse_npy(bytes, "fuzz.npy");
    // What the reader promises: as many values as the shape says, all from the bytes.
    std::size_t count = 1;
    for (const std::size_t d : a.shape) count *= d;
    if (a.data.size() != count || a.data.size() * 4 > size) std::abort();
  } catch (const interpatch::error&) {
    // Bad input, reported as it should be.
  }
  return 0;
}
