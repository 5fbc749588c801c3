// docs/spec-format.md documents exactly the spec forms the reader takes: every
// construction type, curve form and point-array file form (io::spec_forms()), each
// with a field table whose rows are exactly that form's fields.

#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "interpatch/io/spec.hpp"

#ifndef INTERPATCH_DOCS
#error "INTERPATCH_DOCS must name the docs directory"
#endif

namespace interpatch::io {
namespace {

using Documented = std::map<std::string, std::set<std::string>>;  // "kind name" -> fields

// Sections headed "### type `name`", "### curve `name`" or "### points `name`", and
// the first column of the table rows under them: "| `field` |". Names with a slash
// are nested fields, documented but not top-level.
Documented read_documented(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in) << "cannot read " << path;
  const std::regex heading(R"(^### (type|curve|points|sampling) `([a-z_0-9]+)`\s*$)");
  const std::regex other_heading(R"(^#{1,6} )");
  const std::regex row(R"(^\| `([^`]+)` \|)");
  Documented doc;
  std::string line, current;
  std::smatch m;
  while (std::getline(in, line)) {
    if (std::regex_match(line, m, heading)) {
      current = m[1].str() + " " + m[2].str();
      EXPECT_FALSE(doc.count(current)) << current << " is documented twice";
      doc[current];
    } else if (std::regex_search(line, other_heading)) {
      current.clear();
    } else if (!current.empty() && std::regex_search(line, m, row) && m[1].str().find('/') == std::string::npos) {
      doc[current].insert(m[1].str());
    }
  }
  return doc;
}

std::string joined(const std::set<std::string>& s) {
  std::string r;
  for (const auto& x : s) r += (r.empty() ? "" : ", ") + x;
  return r;
}

TEST(SpecFormat, DocumentsEveryFormAndItsFieldsExactly) {
  const Documented doc = read_documented(std::string(INTERPATCH_DOCS) + "/spec-format.md");
  Documented parser;
  for (const SpecForm& f : spec_forms()) {
    auto& fields = parser[std::string(f.kind) + " " + std::string(f.name)];
    fields.insert(f.fields.begin(), f.fields.end());
  }
  for (const auto& [form, fields] : parser) {
    const auto it = doc.find(form);
    if (it == doc.end()) {
      ADD_FAILURE() << form << " is read by interpatch but has no section in docs/spec-format.md";
      continue;
    }
    EXPECT_EQ(it->second, fields) << form << ": documented fields {" << joined(it->second)
                                  << "}, read fields {" << joined(fields) << "}";
  }
  for (const auto& [form, fields] : doc)
    EXPECT_TRUE(parser.count(form)) << form << " is documented but interpatch does not read it";
}

TEST(SpecFormat, EveryTypeIsAForm) {
  std::set<std::string> types;
  for (const SpecForm& f : spec_forms())
    if (f.kind == "type") types.insert(std::string(f.name));
  std::set<std::string> known;
  for (auto t : known_types()) known.insert(std::string(t));
  EXPECT_EQ(types, known);
  // A type's fields are its top-level ones: "type" first, none twice.
  for (const SpecForm& f : spec_forms()) {
    if (f.kind != "type") continue;
    ASSERT_FALSE(f.fields.empty()) << f.name;
    EXPECT_EQ(f.fields.front(), "type") << f.name;
    EXPECT_EQ(std::set<std::string_view>(f.fields.begin(), f.fields.end()).size(), f.fields.size()) << f.name;
  }
}

}  // namespace
}  // namespace interpatch::io
