// What a front end builds: a spec file, or a data file of points standing for the
// spec that interpolates them.

#include "interpatch/io/input.hpp"

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "interpatch/error.hpp"
#include "interpatch/io/npy.hpp"
#include "io/extension.hpp"

namespace interpatch::io {

namespace fs = std::filesystem;

namespace {

// A shape as NumPy prints it: (4, 3), (5,).
std::string shape_text(const std::vector<std::size_t>& shape) {
  std::string s = "(";
  for (std::size_t i = 0; i < shape.size(); ++i) s += (i ? ", " : "") + std::to_string(shape[i]);
  return s + (shape.size() == 1 ? ",)" : ")");
}

// The shape of a .npy file, from its header alone; nullopt when the header cannot
// be read (the build of the spec reports why).
std::optional<std::vector<std::size_t>> npy_shape(const fs::path& file) {
  struct header_read {
    std::vector<std::size_t> shape;
  };
  try {
    // The destination is asked for once the header is read and checked against the
    // file's size: refusing it there leaves the data unread.
    (void)read_npy_into(file, [](std::span<const std::size_t> shape, std::size_t) -> double* {
      throw header_read{{shape.begin(), shape.end()}};
    });
  } catch (const header_read& h) {
    return h.shape;
  } catch (const error&) {
    return std::nullopt;
  }
  return std::nullopt;  // not reached: read_npy_into asks for the memory of every array it reads
}

}  // namespace

Input::Kind input_kind(const fs::path& path) {
  const std::string ext = internal::lower_extension(path);
  return ext == ".npy" ? Input::Kind::npy : ext == ".csv" ? Input::Kind::csv : Input::Kind::spec;
}

nlohmann::json data_file_spec(const Input& in) {
  const std::string file = in.path.filename().string();
  if (in.kind == Input::Kind::csv)
    return {{"type", in.shape.size() == 3 ? "interpolate_volume" : "interpolate"},
            {"points", {{"csv", file}, {"shape", in.shape}}}};
  const std::optional<std::vector<std::size_t>> shape = npy_shape(in.path);
  if (shape && shape->size() != 3 && shape->size() != 4)
    throw error(errc::size_mismatch, in.path.string() + " has shape " + shape_text(*shape) +
                                         ": points to interpolate are an array of shape (n, m, 3) (a surface) "
                                         "or (n, m, l, 3) (a volume)");
  return {{"type", shape && shape->size() == 4 ? "interpolate_volume" : "interpolate"}, {"points", {{"npy", file}}}};
}

Construction build_input(const Input& in, const BuildOptions& options) {
  if (in.kind == Input::Kind::spec) return build_file(in.path, options);
  return build(data_file_spec(in), in.path.parent_path(), options);
}

Built build_any_input(const Input& in, const BuildOptions& options) {
  if (in.kind != Input::Kind::spec) return build_input(in, options);
  return build_any_file(in.path, options);
}

}  // namespace interpatch::io
