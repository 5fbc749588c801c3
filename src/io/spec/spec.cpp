// The spec reader's front: the table of construction types (made from types.def),
// and the public functions of io/spec.hpp.

#include "interpatch/io/spec.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>

#include "base/excerpt.hpp"
#include "interpatch/blended_surface.hpp"
#include "interpatch/memory.hpp"
#include "io/spec/forms.hpp"
#include "io/spec/reader.hpp"

namespace interpatch::io {

namespace reader {

namespace {

double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

#define INTERPATCH_SPEC_TYPE(name, dims, ...) constexpr std::string_view name##_fields[] = {__VA_ARGS__};
#include "io/spec/types.def"
#undef INTERPATCH_SPEC_TYPE

constexpr ConstructionType construction_types[] = {
#define INTERPATCH_SPEC_TYPE(name, dims, ...) {#name, build_##name, dims, name##_fields},
#include "io/spec/types.def"
#undef INTERPATCH_SPEC_TYPE
};

// How many times the spec names each in-memory array ({"array": NAME}): an array
// named once can be taken rather than copied (BuildOptions::arrays).
void count_array_uses(const json& j, std::map<std::string, std::size_t, std::less<>>& uses) {
  if (j.is_object()) {
    if (const auto it = j.find("array"); it != j.end() && it->is_string()) ++uses[it->get<std::string>()];
    for (const auto& member_value : j) count_array_uses(member_value, uses);
  } else if (j.is_array()) {
    for (const auto& element : j)
      if (element.is_structured()) count_array_uses(element, uses);
  }
}

constexpr std::string_view curve_keys[] = {"interpolate", "bspline", "hermite", "line", "approximate"};

// Counts the uses of the in-memory arrays the spec names. An array the spec never
// names is a field given twice (inline, or from a file, as well) or misnamed:
// refused rather than ignored.
void count_arrays(const json& spec, Context& ctx) {
  if (ctx.arrays && !ctx.arrays->empty()) count_array_uses(spec, ctx.array_uses);
  if (ctx.arrays)
    for (const auto& [name, array] : *ctx.arrays)
      if (!ctx.array_uses.contains(name))
        fail(errc::wrong_type, "arrays: \"", name, "\" is given but the spec names no {\"array\": \"", name, "\"}");
}

void finish(Timings& t, const Context& ctx) {
  const auto done = Clock::now();
  const auto parsed = ctx.parsed_at.value_or(done);
  t.parse_ms = ms_between(ctx.start, parsed);
  t.build_ms = ms_between(parsed, done);
}

// The construction of a spec whose arrays are counted.
Construction build_counted(const json& spec, Context& ctx) {
  if (!spec.is_object())
    fail(errc::wrong_type, "(top level): the spec must be a JSON object with a \"type\", got ", kind(spec));
  if (is_curve_spec(spec))
    fail(errc::missing_field, "(top level): the spec is a curve, not a construction with a \"type\"; a curve spec is "
         "built as a curve (build_curve)");
  const json& t = member(spec, "type", "", cat("a string, one of ", type_list()));
  if (!t.is_string()) wrong_type("/type", cat("a string, one of ", type_list()), t);
  const auto& name = t.get_ref<const std::string&>();
  const ConstructionType* type = find_type(name);
  if (!type)
    fail(errc::unknown_type, "/type: unknown type \"", interpatch::detail::excerpt(name), "\"; known types: ", type_list());
  std::vector<std::string_view> fields(type->fields.begin(), type->fields.end());
  fields.push_back("sampling");  // every construction's: how mesh, eval and view sample it
  check_fields(spec, "", fields, ctx);
  std::optional<Sampling> sampling;
  if (const json* s = find_member(spec, "sampling"))
    sampling = read_sampling(*s, "/sampling", static_cast<std::size_t>(type->dims), ctx);
  Construction c = type->build(spec, ctx);
  c.sampling = sampling;
  if (!ctx.defer_exact && c.convert) (void)has_exact_form_after_conversion(c);
  c.type = name;
  c.warnings = std::move(ctx.warnings);
  finish(c.timings, ctx);
  return c;
}

Construction build_impl(const json& spec, Context& ctx) {
  count_arrays(spec, ctx);
  return build_counted(spec, ctx);
}

CurveConstruction build_curve_impl(const json& spec, Context& ctx) {
  count_arrays(spec, ctx);
  SpecCurve r = read_curve(spec, "", ctx);
  CurveConstruction c{std::string(r.form), std::move(r.curve), {}, std::move(r.parameters), std::move(ctx.warnings), {}};
  if (!r.points.empty()) {
    DataSet d{{std::move(r.params)}, PointStorage(r.points.begin(), r.points.end()), {}, child("", r.form)};
    if (r.form == "hermite") d.pointer = "/hermite/points";
    c.data.push_back(std::move(d));
  }
  finish(c.timings, ctx);
  return c;
}

// The context of a build: data files relative to `base_dir`, and the options.
void set_options(Context& ctx, const std::filesystem::path& base_dir, const BuildOptions& options) {
  ctx.base_dir = base_dir;
  ctx.progress = options.progress;
  ctx.keep_data = options.keep_data;
  ctx.defer_exact = options.defer_exact;
  ctx.arrays = &options.arrays;
  ctx.borrow_arrays = options.borrow_arrays;
}

std::pair<std::size_t, std::size_t> line_column(std::string_view text, std::size_t pos) {
  pos = std::min(pos, text.size());
  std::size_t line = 1, start = 0;
  for (std::size_t i = 0; i < pos; ++i)
    if (text[i] == '\n') {
      ++line;
      start = i + 1;
    }
  return {line, pos - start + 1};
}

}  // namespace

Construction build_block(const json& spec, std::string_view pointer, Context& ctx) {
  if (!spec.is_object()) wrong_type(pointer, "a volume spec, an object with a \"type\"", spec);
  if (const json* t = find_member(spec, "type"); t && t->is_string()) {
    const ConstructionType* type = find_type(t->get<std::string>());
    if (type && (type->dims != 3 || type->name == "blocks"))
      fail(errc::wrong_type, pointer, "/type: a block is a volume of one of the types ", type_list(3),
           " but blocks; \"", type->name, "\" is ", type->dims == 3 ? "blocks itself" : "a surface");
  }
  std::vector<std::string> outer = std::exchange(ctx.warnings, {});
  const auto parsed_at = ctx.parsed_at;
  Construction c;
  try {
    c = build_counted(spec, ctx);
  } catch (const error& e) {
    // The builders name places from the spec's top: from the block's, here.
    const std::string what = e.what();
    throw error(e.code(), what.starts_with("/") ? cat(pointer, what) : cat(pointer, ": ", what));
  }
  ctx.parsed_at = parsed_at;
  for (std::string& w : c.warnings) outer.push_back(w.starts_with("/") ? cat(pointer, w) : cat(pointer, ": ", w));
  c.warnings.clear();
  ctx.warnings = std::move(outer);
  return c;
}

const ConstructionType* find_type(std::string_view name) {
  const auto it = std::find_if(std::begin(construction_types), std::end(construction_types),
                               [&](const ConstructionType& c) { return c.name == name; });
  return it == std::end(construction_types) ? nullptr : &*it;
}

std::string type_list(int dims) {
  std::string s;
  for (const auto& t : construction_types)
    if (dims == 0 || t.dims == dims) s += cat(s.empty() ? "" : ", ", t.name);
  return s;
}

}  // namespace reader

using namespace reader;

std::vector<std::string_view> known_types() {
  std::vector<std::string_view> v;
  for (const auto& t : construction_types) v.push_back(t.name);
  return v;
}

std::vector<SpecForm> spec_forms() {
  std::vector<SpecForm> v;
  auto add = [&](std::string_view kind, std::string_view name, Fields fields) {
    v.push_back({kind, name, std::vector<std::string_view>(fields.begin(), fields.end())});
  };
  for (const auto& t : construction_types) add("type", t.name, t.fields);
  add("curve", "interpolate", forms::interpolate_curve);
  add("curve", "bspline", forms::bspline_curve);
  add("curve", "hermite", forms::hermite_curve);
  add("curve", "line", forms::line_curve);
  add("curve", "approximate", forms::approximate_curve);
  add("points", "npy", forms::npy);
  add("points", "csv", forms::csv);
  add("sampling", "direction", forms::sampling_direction);
  return v;
}

namespace {

// Why nlohmann refused `text` (all that was read, up to the byte it stopped at), as
// interpatch's error with line and column.
[[noreturn]] void fail_unparsed(std::string_view text, std::string_view source) {
  try {
    throw;
  } catch (const json::parse_error& e) {
    // e.byte is the 1-based offset of the last character read.
    std::size_t pos = e.byte == 0 ? 0 : std::min<std::size_t>(e.byte - 1, text.size());
    // A literal the lexer stopped in: back up to where the word starts.
    std::size_t start = pos;
    while (start > 0 && std::isalpha(static_cast<unsigned char>(text[start - 1]))) --start;
    std::size_t end = start;
    while (end < text.size() && std::isalpha(static_cast<unsigned char>(text[end]))) ++end;
    const std::string_view word = text.substr(start, end - start);
    if (word == "NaN" || word == "nan" || word == "Infinity" || word == "inf" || word == "infinity" || word == "Inf") {
      const bool minus = start > 0 && text[start - 1] == '-';
      const auto [line, col] = line_column(text, minus ? start - 1 : start);
      fail(errc::not_finite, source, ":", line, ":", col, ": ", minus ? "-" : "", word,
           " is not a JSON number; coordinates, knots and weights must be finite");
    }
    const auto [line, col] = line_column(text, pos);
    std::string what = e.what();
    // Keep nlohmann's description, drop its prefix with its own position.
    if (const auto c = what.find("column "); c != std::string::npos)
      if (const auto colon = what.find(": ", c); colon != std::string::npos) what = what.substr(colon + 2);
    // nlohmann quotes what it read last, which may be any bytes of any length.
    fail(errc::invalid_json, source, ":", line, ":", col, ": invalid JSON: ", interpatch::detail::excerpt(what, 160));
  } catch (const json::out_of_range& e) {
    // A number beyond the range of double (1e999); nlohmann names the token only.
    const std::string what = e.what();
    std::string token;
    if (const auto q = what.find('\''); q != std::string::npos)
      if (const auto q2 = what.find('\'', q + 1); q2 != std::string::npos) token = what.substr(q + 1, q2 - q - 1);
    const std::size_t pos = token.empty() ? std::string_view::npos : text.find(token);
    if (pos == std::string_view::npos) fail(errc::not_finite, source, ": a number is too large for a double");
    const auto [line, col] = line_column(text, pos);
    fail(errc::not_finite, source, ":", line, ":", col, ": number ", interpatch::detail::excerpt(token, 40), " is too large for a double");
  }
}

// The characters of a stream for nlohmann's parser, one at a time, kept in `text` for
// the error's line and column; past `limit` bytes, too_large. A pipe or a device has
// no size to check before reading and may never end (/dev/zero, `yes`): the parser
// stops at its first bad byte, and a stream of valid JSON that goes on stops here.
class BoundedChars {
 public:
  using iterator_category = std::input_iterator_tag;
  using value_type = char;
  using difference_type = std::ptrdiff_t;
  using pointer = const char*;
  using reference = const char&;

  BoundedChars() = default;
  BoundedChars(std::streambuf* in, std::string* text, std::size_t limit, std::string_view source)
      : in_(in), text_(text), limit_(limit), source_(source) {
    take();
  }
  const char& operator*() const { return text_->back(); }
  BoundedChars& operator++() {
    take();
    return *this;
  }
  void operator++(int) { take(); }
  bool operator==(const BoundedChars& o) const { return at_end() == o.at_end(); }

 private:
  bool at_end() const { return in_ == nullptr; }
  void take() {
    if (in_ == nullptr) return;
    const auto c = in_->sbumpc();
    if (std::streambuf::traits_type::eq_int_type(c, std::streambuf::traits_type::eof())) {
      in_ = nullptr;
      return;
    }
    if (text_->size() >= limit_)
      fail(errc::too_large, source_, ": a spec read from a pipe or device is at most ", limit_ >> 20,
           " MiB of JSON, and this one goes on past that; large point sets go in .npy or .csv files");
    text_->push_back(std::streambuf::traits_type::to_char_type(c));
  }

  std::streambuf* in_ = nullptr;
  std::string* text_ = nullptr;
  std::size_t limit_ = 0;
  std::string_view source_;
};

}  // namespace

json parse_json(std::string_view text, std::string_view source) {
  try {
    return json::parse(text.begin(), text.end());
  } catch (const std::exception&) {
    fail_unparsed(text, source);
  }
}

json read_json_file(const std::filesystem::path& path) {
  std::error_code ec;
  const std::string name = path.string();
  if (!std::filesystem::exists(path, ec)) fail(errc::file_unreadable, name, ": cannot read: no such file");
  if (std::filesystem::is_directory(path, ec)) fail(errc::file_unreadable, name, ": cannot read: it is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(errc::file_unreadable, name, ": cannot open: ", std::strerror(errno));
  if (!std::filesystem::is_regular_file(path, ec)) {
    std::string text;
    try {
      return json::parse(BoundedChars(in.rdbuf(), &text, max_streamed_spec_bytes, name), BoundedChars());
    } catch (const error&) {
      throw;
    } catch (const std::exception&) {
      fail_unparsed(text, name);
    }
  }
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec && size > max_spec_bytes)
    fail(errc::too_large, name, ": a JSON spec of ", size, " bytes is more than the ", max_spec_bytes >> 20,
         " MiB a spec may be; large point sets go in .npy or .csv files");
  // The parsed document takes a few times the text; refuse what cannot fit.
  if (!ec) require_memory(static_cast<std::size_t>(size), 4, cat(name, ": a JSON spec of ", size, " bytes"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) fail(errc::file_unreadable, name, ": read error: ", std::strerror(errno));
  return parse_json(text, name);
}

bool is_volume(const Construction& c) noexcept {
  if (c.blocks) return true;
  return c.exact ? std::holds_alternative<BSplineVolume>(*c.exact) : c.volume_formula != nullptr;
}

const ExactForm& exact_form(Construction& c, const progress_callback& progress) {
  if (!c.exact && c.convert) {
    try {
      c.exact = c.convert(progress);
      c.convert = nullptr;
    } catch (const error& e) {
      // A conversion refused (its check found it off): the construction keeps its
      // formula, and what asks for the exact form is told why. Anything else (an
      // interrupt from the progress callback, memory) leaves it to be made again.
      if (e.code() != errc::no_exact_form) throw;
      c.convert = nullptr;
      c.no_exact_form = e.what();
    }
  }
  if (!c.exact) fail(errc::no_exact_form, c.type, ": ", c.no_exact_form);
  return *c.exact;
}

bool has_exact_form(const Construction& c) noexcept { return c.exact || c.convert; }

bool has_exact_form_after_conversion(Construction& c, const progress_callback& progress) {
  try {
    (void)exact_form(c, progress);
    return true;
  } catch (const error& e) {
    if (e.code() != errc::no_exact_form) throw;
    return false;
  }
}

const Surface& evaluator(const Construction& c) {
  if (is_volume(c)) fail(errc::wrong_type, c.type, ": the construction is a volume, not a surface");
  if (c.exact) return std::get<BSplineSurface>(*c.exact);
  if (!c.formula) fail(errc::internal, c.type, ": the construction has neither an exact form nor a formula");
  return *c.formula;
}

const Surface& evaluator(Construction& c, std::size_t points, Sample what) {
  if (c.exact || !c.convert) return evaluator(c);
  const auto* blended = dynamic_cast<const BlendedSurface*>(c.formula.get());
  if (blended == nullptr) return evaluator(c);
  // Operations per point, up to a common factor: a term of the formula is one
  // product (six with derivatives); the exact form's batch evaluation is about
  // (p + 1) + (q + 1) products per point (six times that with derivatives), after
  // one sum of the terms per control point to make it.
  const auto knots = blended->exact_knots();
  const double w = what == Sample::derivatives ? 6 : 1, n = static_cast<double>(points);
  const double terms = static_cast<double>(blended->terms());
  const double net = static_cast<double>(knots[0].count()) * static_cast<double>(knots[1].count());
  const double by_formula = n * terms * w;
  const double by_exact = net * terms + n * (knots[0].degree() + knots[1].degree() + 2) * w;
  if (by_exact < by_formula) (void)has_exact_form_after_conversion(c);
  return evaluator(c);
}

const Volume& volume_evaluator(const Construction& c) {
  if (!is_volume(c)) fail(errc::wrong_type, c.type, ": the construction is a surface, not a volume");
  if (c.blocks)
    fail(errc::wrong_type, c.type, ": ", c.blocks->blocks.size(), " volumes, not one: they are meshed together (mesh "
         "-o .vtu, .msh or CASE/constant/polyMesh) and described (info); each block's own spec does the rest");
  if (c.exact) return std::get<BSplineVolume>(*c.exact);
  return *c.volume_formula;
}

Construction build(const json& spec, const std::filesystem::path& base_dir, const BuildOptions& options) {
  Context ctx;
  set_options(ctx, base_dir, options);
  return build_impl(spec, ctx);
}

Construction build(const json& spec, const std::filesystem::path& base_dir, const progress_callback& progress,
                   bool keep_data) {
  return build(spec, base_dir, BuildOptions{.progress = progress, .keep_data = keep_data, .defer_exact = false, .arrays = {}});
}

Construction build_file(const std::filesystem::path& spec_path, const BuildOptions& options) {
  Context ctx;  // starts the clock: reading the file counts as parsing
  const json spec = read_json_file(spec_path);
  set_options(ctx, spec_path.parent_path(), options);
  return build_impl(spec, ctx);
}

Construction build_file(const std::filesystem::path& spec_path, const progress_callback& progress, bool keep_data) {
  return build_file(spec_path, BuildOptions{.progress = progress, .keep_data = keep_data, .defer_exact = false, .arrays = {}});
}

PointArray points_from_json(const json& j, std::size_t rank, const std::filesystem::path& base_dir, std::string_view pointer) {
  if (rank < 1 || rank > 3) fail(errc::internal, "points_from_json: rank ", rank, " is outside 1..3");
  Context ctx;
  ctx.base_dir = base_dir;
  return points_impl(j, rank, pointer, ctx);
}

bool is_curve_spec(const json& spec) noexcept {
  if (!spec.is_object() || spec.contains("type")) return false;
  return std::any_of(std::begin(curve_keys), std::end(curve_keys), [&](std::string_view k) { return spec.contains(k); });
}

CurveConstruction build_curve(const json& spec, const std::filesystem::path& base_dir, const BuildOptions& options) {
  Context ctx;
  set_options(ctx, base_dir, options);
  return build_curve_impl(spec, ctx);
}

Built build_any(const json& spec, const std::filesystem::path& base_dir, const BuildOptions& options) {
  Context ctx;
  set_options(ctx, base_dir, options);
  if (is_curve_spec(spec)) return build_curve_impl(spec, ctx);
  return build_impl(spec, ctx);
}

Built build_any_file(const std::filesystem::path& spec_path, const BuildOptions& options) {
  Context ctx;  // starts the clock: reading the file counts as parsing
  const json spec = read_json_file(spec_path);
  set_options(ctx, spec_path.parent_path(), options);
  if (is_curve_spec(spec)) return build_curve_impl(spec, ctx);
  return build_impl(spec, ctx);
}

BSplineCurve curve_from_json(const json& j, const std::filesystem::path& base_dir, std::string_view pointer) {
  Context ctx;
  ctx.base_dir = base_dir;
  return curve_impl(j, pointer, ctx);
}

}  // namespace interpatch::io
