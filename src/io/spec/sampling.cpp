// A spec's "sampling": the nodes of mesh, eval and view along each direction.

#include "interpatch/io/spec.hpp"
#include "base/excerpt.hpp"
#include "io/spec/forms.hpp"
#include "io/spec/reader.hpp"

namespace interpatch::io {
namespace reader {

Sampling read_sampling(const json& j, std::string_view ptr, std::size_t dims, Context& ctx) {
  expect_object(j, ptr, dims == 2 ? "an object of directions u, v" : "an object of directions u, v, w");
  Sampling s;
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string& key = it.key();
    const std::string p = child(ptr, key);
    std::size_t d = 0;
    while (d < dims && key != axis_name(d)) ++d;
    if (d == dims) {
      if (key == "comment" || key == "description") continue;
      fail(errc::invalid_grading, place(p), ": ", dims == 2 ? "a surface" : "a volume", " has no direction \"",
           interpatch::detail::excerpt(key), "\"; its directions are ", dims == 2 ? "u and v" : "u, v and w");
    }
    const json& o = *it;
    expect_object(o, p, "an object with count, ratio, first, last or max_growth");
    check_fields(o, p, forms::sampling_direction, ctx);
    Grading& g = s[d];
    if (const json* c = find_member(o, "count")) {
      const std::int64_t n = integer(*c, child(p, "count"), "a count of nodes");
      if (n < 2)
        fail(errc::too_few_points, place(child(p, "count")), ": ", n,
             "; a mesh needs at least 2 nodes along each direction");
      g.count = static_cast<std::size_t>(n);
    }
    auto positive = [&](const char* field, double& out) {
      if (const json* v = find_member(o, field)) {
        out = number(*v, child(p, field));
        if (!(out > 0))
          fail(errc::invalid_grading, place(child(p, field)), ": ", out, "; it must be a positive length or ratio");
      }
    };
    positive("ratio", g.ratio);
    positive("first", g.first);
    positive("last", g.last);
    if (const json* v = find_member(o, "max_growth")) {
      g.max_growth = number(*v, child(p, "max_growth"));
      if (!(g.max_growth > 1))
        fail(errc::invalid_grading, place(child(p, "max_growth")), ": ", g.max_growth,
             "; neighbouring cells must be allowed to grow: give a number above 1");
    }
    if (g.ratio != 0 && (g.first != 0 || g.last != 0))
      fail(errc::invalid_grading, place(p), ": ratio is given with ", g.first != 0 ? "first" : "last",
           "; give the ratio, or the end lengths");
  }
  return s;
}

}  // namespace reader

Sampling read_sampling(const nlohmann::json& j, std::size_t dims) {
  reader::Context ctx;
  Sampling s = reader::read_sampling(j, "/sampling", dims, ctx);
  return s;
}

}  // namespace interpatch::io
