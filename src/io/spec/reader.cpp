#include "io/spec/reader.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "base/excerpt.hpp"

namespace interpatch::io::reader {

std::string child(std::string_view ptr, std::string_view key) {
  std::string s(ptr);
  s += '/';
  for (const char c : key) {
    if (c == '~') s += "~0";
    else if (c == '/') s += "~1";
    else s += c;
  }
  return s;
}

std::string child(std::string_view ptr, std::size_t index) {
  std::string s(ptr);
  s += '/';
  s += std::to_string(index);
  return s;
}

std::string index_pointer(std::string_view ptr, const std::vector<std::size_t>& idx, std::size_t n) {
  std::string s(ptr);
  for (std::size_t k = 0; k < n; ++k) {
    s += '/';
    s += std::to_string(idx[k]);
  }
  return s;
}

std::string place(std::string_view ptr) {
  if (ptr.empty()) return "(top level)";
  return interpatch::detail::excerpt(ptr);
}

const char* kind(const json& j) {
  switch (j.type()) {
    case json::value_t::null: return "null";
    case json::value_t::boolean: return "a boolean";
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
    case json::value_t::number_float: return "a number";
    case json::value_t::string: return "a string";
    case json::value_t::array: return "an array";
    case json::value_t::object: return "an object";
    default: return "a binary value";
  }
}

void wrong_type(std::string_view ptr, std::string_view expected, const json& got) {
  fail(errc::wrong_type, place(ptr), ": expected ", expected, ", got ", kind(got));
}

std::string shape_text(std::span<const std::size_t> shape) {
  std::string s = "(";
  for (std::size_t i = 0; i < shape.size(); ++i) s += (i ? ", " : "") + std::to_string(shape[i]);
  return s + (shape.size() == 1 ? ",)" : ")");
}

std::string extents_text(std::span<const std::size_t> shape) {
  std::string s;
  for (std::size_t i = 0; i < shape.size(); ++i) s += (i ? "x" : "") + std::to_string(shape[i]);
  return s;
}

std::size_t checked_product(std::span<const std::size_t> shape, std::string_view what) {
  std::size_t n = 1;
  for (const std::size_t e : shape) {
    if (e != 0 && n > std::numeric_limits<std::size_t>::max() / e)
      fail(errc::too_large, what, ": shape ", shape_text(shape), " has more entries than can be addressed");
    n *= e;
  }
  return n;
}

std::filesystem::path Context::resolve(const std::string& file) const {
  const std::filesystem::path p(file);
  return p.is_absolute() || base_dir.empty() ? p : base_dir / p;
}

const json* find_member(const json& obj, std::string_view key) {
  const auto it = obj.find(std::string(key));
  return it == obj.end() ? nullptr : &*it;
}

const json& member(const json& obj, std::string_view key, std::string_view ptr, std::string_view expected) {
  const json* m = find_member(obj, key);
  if (!m) fail(errc::missing_field, place(child(ptr, key)), ": missing field (expected ", expected, ")");
  return *m;
}

void expect_object(const json& j, std::string_view ptr, std::string_view expected) {
  if (!j.is_object()) wrong_type(ptr, expected, j);
}

void check_fields(const json& obj, std::string_view ptr, Fields known, Context& ctx) {
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    const std::string& k = it.key();
    if (k == "comment" || k == "description" || k == "name") continue;
    if (std::find(known.begin(), known.end(), k) == known.end())
      ctx.warn(cat(place(child(ptr, k)), ": unknown field, ignored"));
  }
}

std::string file_name(const json& obj, std::string_view key, std::string_view ptr) {
  const json& f = member(obj, key, ptr, "a file name");
  if (!f.is_string() || f.get_ref<const std::string&>().empty()) wrong_type(child(ptr, key), "a file name", f);
  return f.get<std::string>();
}

double number(const json& j, std::string_view ptr) {
  if (!j.is_number()) wrong_type(ptr, "a number", j);
  const double v = j.get<double>();
  if (!std::isfinite(v)) fail(errc::not_finite, place(ptr), ": value is ", v);
  return v;
}

std::int64_t integer(const json& j, std::string_view ptr, std::string_view expected) {
  if (j.is_number_unsigned()) {
    const auto u = j.get<std::uint64_t>();
    if (u > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()))
      fail(errc::wrong_type, place(ptr), ": ", u, " is too large; expected ", expected);
    return static_cast<std::int64_t>(u);
  }
  if (j.is_number_integer()) return j.get<std::int64_t>();
  if (j.is_number_float()) {
    const double d = j.get<double>();
    if (std::isfinite(d) && d == std::floor(d) && std::fabs(d) < 9.0e15) return static_cast<std::int64_t>(d);
    fail(errc::wrong_type, place(ptr), ": ", d, " is not an integer; expected ", expected);
  }
  wrong_type(ptr, expected, j);
}

std::vector<double> numbers(const json& j, std::string_view ptr, std::string_view expected) {
  if (!j.is_array()) wrong_type(ptr, expected, j);
  std::vector<double> v(j.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    const json& x = j[i];
    if (x.is_number()) {
      v[i] = x.get<double>();
      if (std::isfinite(v[i])) continue;
    }
    v[i] = number(x, child(ptr, i));  // throws with the entry's place
  }
  return v;
}

Vec3 point_value(const json& j, std::string_view ptr) {
  const std::vector<double> v = numbers(j, ptr, "a point [x, y, z]");
  if (v.size() != 3) fail(errc::wrong_type, place(ptr), ": expected a point [x, y, z], got ", v.size(), " numbers");
  return {v[0], v[1], v[2]};
}

int degree_value(const json& j, std::string_view ptr) {
  const std::int64_t d = integer(j, ptr, "an integer degree");
  if (d < 1 || d > max_degree) fail(errc::invalid_degree, place(ptr), ": degree ", d, " is outside 1..", max_degree);
  return static_cast<int>(d);
}

std::vector<std::optional<int>> degrees(const json& obj, std::string_view ptr, std::size_t dims) {
  std::vector<std::optional<int>> d(dims);
  const json* j = find_member(obj, "degree");
  if (!j) return d;
  const std::string at_ = child(ptr, "degree");
  if (j->is_array()) {
    if (j->size() != dims)
      fail(errc::size_mismatch, place(at_), ": expected ", dims, " degrees (one per direction ",
           dims == 3 ? "u, v, w" : (dims == 2 ? "u, v" : "t"), "), got ", j->size());
    for (std::size_t i = 0; i < dims; ++i) d[i] = degree_value((*j)[i], child(at_, i));
  } else if (j->is_number()) {
    const int v = degree_value(*j, at_);
    for (auto& x : d) x = v;
  } else {
    wrong_type(at_, dims == 1 ? "an integer degree" : cat("an integer degree or an array of ", dims, " degrees"), *j);
  }
  return d;
}

std::string degree_pointer(const json& obj, std::string_view ptr, std::size_t axis) {
  const json* j = find_member(obj, "degree");
  const std::string d = child(ptr, "degree");
  return place(j && j->is_array() ? child(d, axis) : d);
}

const char* param_name(Parametrization p) {
  switch (p) {
    case Parametrization::uniform: return "uniform";
    case Parametrization::chord: return "chord";
    case Parametrization::centripetal: return "centripetal";
  }
  return "chord";
}

Parametrization parametrization(const json& obj, std::string_view ptr) {
  const json* p = find_member(obj, "param");
  if (!p) return Parametrization::chord;
  const std::string at_ = child(ptr, "param");
  if (!p->is_string()) wrong_type(at_, "a string: uniform, chord or centripetal", *p);
  const auto& s = p->get_ref<const std::string&>();
  for (const auto v : {Parametrization::uniform, Parametrization::chord, Parametrization::centripetal})
    if (s == param_name(v)) return v;
  fail(errc::wrong_type, place(at_), ": unknown parametrization \"", interpatch::detail::excerpt(s),
       "\"; expected uniform, chord or centripetal");
}

std::array<bool, 3> periodic_flags(const json& obj, std::string_view ptr, std::size_t dims) {
  std::array<bool, 3> flags{};
  const json* j = find_member(obj, "periodic");
  if (!j) return flags;
  const std::string at_ = child(ptr, "periodic");
  if (dims == 1) {
    if (!j->is_boolean()) wrong_type(at_, "true or false", *j);
    flags[0] = j->get<bool>();
    return flags;
  }
  const std::string form = cat(dims, " booleans [", dims == 3 ? "u, v, w" : "u, v", "], one per direction");
  if (!j->is_array()) wrong_type(at_, cat("an array of ", form), *j);
  if (j->size() != dims) fail(errc::wrong_type, place(at_), ": expected ", form, ", got ", j->size());
  for (std::size_t a = 0; a < dims; ++a) {
    const json& e = (*j)[a];
    if (!e.is_boolean()) wrong_type(child(at_, a), cat("true or false (is ", axis_name(a), " closed?)"), e);
    flags[a] = e.get<bool>();
  }
  return flags;
}

std::string periodic_text(const std::array<bool, 3>& flags, std::size_t dims) {
  std::string s = "[";
  for (std::size_t a = 0; a < dims; ++a) s += cat(a ? ", " : "", flags[a] ? "true" : "false");
  return s + "]";
}

KnotVector knot_vector(int degree, std::vector<double> knots, bool periodic) {
  return periodic ? KnotVector::periodic_from_extended(degree, knots) : KnotVector(degree, std::move(knots));
}

std::string knots_text(const KnotVector& k) {
  return cat(k.size(), k.periodic() ? " periodic knots" : " knots", " of degree ", k.degree());
}

std::optional<double> tolerance_of(const json& spec) {
  const json* t = find_member(spec, "tolerance");
  if (!t) return std::nullopt;
  const double v = number(*t, "/tolerance");
  if (!(v >= 0)) fail(errc::wrong_type, "/tolerance: must not be negative, got ", v);
  return v;
}

std::string choice(const json& obj, std::string_view key, std::string_view ptr,
                   std::initializer_list<std::string_view> allowed, std::string_view fallback) {
  const json* m = find_member(obj, key);
  if (!m) return std::string(fallback);
  std::string list;
  for (auto a : allowed) list += cat(list.empty() ? "\"" : ", \"", a, "\"");
  if (!m->is_string()) wrong_type(child(ptr, key), cat("one of ", list), *m);
  const auto& v = m->get_ref<const std::string&>();
  if (std::find(allowed.begin(), allowed.end(), v) == allowed.end())
    fail(errc::wrong_type, place(child(ptr, key)), ": unknown value \"", interpatch::detail::excerpt(v),
         "\"; expected one of ", list);
  return v;
}

std::vector<double> to_unit(std::vector<double> t, std::pair<double, double> domain) {
  const auto [a, b] = domain;
  if (a == 0.0 && b == 1.0) return t;
  for (double& x : t) x = std::clamp((x - a) / (b - a), 0.0, 1.0);
  return t;
}

}  // namespace interpatch::io::reader
