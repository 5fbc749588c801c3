// "blocks": volumes meshed together. Each block is a volume spec of its own; the
// faces they share are found when they are meshed (io/blocks.cpp), by geometry.

#include <algorithm>
#include <cctype>

#include "io/spec/reader.hpp"

namespace interpatch::io::reader {

namespace {

constexpr const char* face_names[] = {"u0", "u1", "v0", "v1", "w0", "w1"};

// OpenFOAM reads a patch name as a word: a letter or _ first, then letters, digits, _.
bool is_word(std::string_view w) {
  if (w.empty() || !(std::isalpha(static_cast<unsigned char>(w[0])) || w[0] == '_')) return false;
  return std::all_of(w.begin(), w.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

std::vector<std::string> block_names(const json& blocks) {
  std::vector<std::string> names;
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const std::string ptr = cat("/blocks/", k, "/name");
    std::string name = cat("block", k);
    if (const json* n = find_member(blocks[k], "name")) {
      if (!n->is_string()) wrong_type(ptr, "a name: a letter or _, then letters, digits and _", *n);
      name = n->get<std::string>();
      if (!is_word(name))
        fail(errc::wrong_type, ptr, ": \"", name, "\" is not a name OpenFOAM reads: a letter or _, then letters, "
             "digits and _");
    }
    if (std::find(names.begin(), names.end(), name) != names.end())
      fail(errc::wrong_type, ptr, ": \"", name, "\" names two blocks");
    names.push_back(std::move(name));
  }
  return names;
}

// Each face's patch: NAME_FACE, unless "patches" ({"inlet": ["duct_w0", ...]}) names it.
std::vector<std::array<std::string, 6>> patch_names(const json* patches, const std::vector<std::string>& names) {
  std::vector<std::array<std::string, 6>> p(names.size());
  for (std::size_t b = 0; b < names.size(); ++b)
    for (std::size_t f = 0; f < 6; ++f) p[b][f] = cat(names[b], "_", face_names[f]);
  if (!patches) return p;
  expect_object(*patches, "/patches", "an object: patch name -> the block faces in it, [\"NAME_w0\", ...]");
  std::vector<std::array<bool, 6>> named(names.size(), std::array<bool, 6>{});
  for (const auto& [patch, faces] : patches->items()) {
    const std::string ptr = cat("/patches/", patch);
    if (!is_word(patch))
      fail(errc::wrong_type, ptr, ": \"", patch, "\" is not a name OpenFOAM reads: a letter or _, then letters, "
           "digits and _");
    if (!faces.is_array() || faces.empty()) wrong_type(ptr, "a non-empty array of block faces, [\"NAME_w0\", ...]", faces);
    for (std::size_t i = 0; i < faces.size(); ++i) {
      const std::string fptr = cat(ptr, "/", i);
      if (!faces[i].is_string()) wrong_type(fptr, "a block face, \"NAME_w0\"", faces[i]);
      const std::string face = faces[i].get<std::string>();
      bool found = false;
      for (std::size_t b = 0; b < names.size() && !found; ++b)
        for (std::size_t f = 0; f < 6 && !found; ++f)
          if (face == cat(names[b], "_", face_names[f])) {
            found = true;
            if (named[b][f]) fail(errc::wrong_type, fptr, ": \"", face, "\" is in two patches");
            named[b][f] = true;
            p[b][f] = patch;
          }
      if (!found)
        fail(errc::wrong_type, fptr, ": no block face \"", face, "\"; a face is a block's name and one of _u0 _u1 _v0 "
             "_v1 _w0 _w1 (", names.front(), "_u0 ...)");
    }
  }
  return p;
}

}  // namespace

Construction build_blocks(const json& spec, Context& ctx) {
  const json& blocks = member(spec, "blocks", "", "an array of volume specs");
  if (!blocks.is_array() || blocks.empty()) wrong_type("/blocks", "a non-empty array of volume specs", blocks);
  auto set = std::make_shared<BlockSet>();
  set->names = block_names(blocks);
  set->patches = patch_names(find_member(spec, "patches"), set->names);
  set->tolerance = tolerance_of(spec).value_or(0.0);
  ctx.parsed();
  for (std::size_t k = 0; k < blocks.size(); ++k) set->blocks.push_back(build_block(blocks[k], cat("/blocks/", k), ctx));
  Construction c;
  c.no_exact_form = "a blocks spec has an exact form per block: build each block's spec";
  c.parameters = {{"blocks", blocks.size()}, {"tolerance", set->tolerance}};
  c.blocks = std::move(set);
  return c;
}

}  // namespace interpatch::io::reader
