// Every registered variant carries a well-formed BibTeX entry for the paper
// behind it (`mpmtb list --bibtex`), and shared papers are one entry.
#include <gtest/gtest.h>

#include <set>

#include "citations.hpp"
#include "core/errors.hpp"
#include "core/registry.hpp"
#include "models/registry.hpp"

namespace mpmtb {
namespace citations_test {

// Braces balance and never close below zero.
bool balanced(const std::string& s) {
  int depth = 0;
  for (char c : s) {
    depth += (c == '{') - (c == '}');
    if (depth < 0) return false;
  }
  return depth == 0;
}

void expect_valid(const std::string& who, const std::string& bibtex) {
  SCOPED_TRACE(who);
  ASSERT_FALSE(bibtex.empty());
  EXPECT_EQ(bibtex.front(), '@');
  EXPECT_TRUE(balanced(bibtex));
  const auto entries = parse_bibtex(bibtex, who);
  ASSERT_FALSE(entries.empty());
  for (const auto& e : entries) {
    SCOPED_TRACE(e.key);
    EXPECT_FALSE(e.key.empty());
    const std::set<std::string> fields(e.fields.begin(), e.fields.end());
    for (const char* required : {"author", "title", "year"}) EXPECT_TRUE(fields.count(required));
    EXPECT_TRUE(fields.count("journal") || fields.count("booktitle") || fields.count("publisher"));
  }
}

TEST(Citations, EveryRegisteredVariantHasAValidEntry) {
  for (const auto& t : transfer_list()) expect_valid("transfer " + t.name, t.bibtex);
  for (const auto& k : kernel_list()) expect_valid("kernel " + k.name, k.bibtex);
  for (const auto& m : model_list()) expect_valid("model " + m.name, m.bibtex);
}

TEST(Citations, ListingHasEachKeyOnceWithTheVariantsItBacks) {
  const auto citations = registered_citations();  // throws if one key has two texts
  std::set<std::string> keys;
  std::size_t backed = 0;
  for (const auto& c : citations) {
    EXPECT_TRUE(keys.insert(c.entry.key).second) << c.entry.key;
    backed += c.backs.size();
  }
  // Every variant is backed by at least one entry.
  EXPECT_GE(backed, transfer_list().size() + kernel_list().size() + model_list().size());
  const std::string text = bibtex_listing();
  for (const auto& k : keys) EXPECT_NE(text.find("{" + k + ","), std::string::npos) << k;
}

TEST(Citations, MalformedEntriesAreRejected) {
  EXPECT_THROW(parse_bibtex("article{x, title = {a}}", "t"), InputError);  // no '@'
  EXPECT_THROW(parse_bibtex("@article{x, title = {a}", "t"), InputError);  // not closed
  EXPECT_THROW(parse_bibtex("@article{, title = {a}}", "t"), InputError);  // no key
  const auto two = parse_bibtex("@book{a, title = {T}, year = 2008}\n@misc{b, note = {n}}", "t");
  ASSERT_EQ(two.size(), 2u);
  EXPECT_EQ(two[0].fields, (std::vector<std::string>{"title", "year"}));
  EXPECT_EQ(two[1].key, "b");
}

}  // namespace citations_test
}  // namespace mpmtb
