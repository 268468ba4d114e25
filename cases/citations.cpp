#include "citations.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cctype>

#include "core/errors.hpp"
#include "core/registry.hpp"
#include "models/registry.hpp"

namespace mpmtb {
namespace {

bool space(char c) {
  return std::isspace(static_cast<unsigned char>(c)) != 0;
}

std::string word(std::string_view s, std::size_t& i) {
  while (i < s.size() && space(s[i])) ++i;
  std::string w;
  while (i < s.size() && (std::isalnum(static_cast<unsigned char>(s[i])) || s[i] == '_' ||
                          s[i] == '-' || s[i] == ':' || s[i] == '.')) {
    w += static_cast<char>(std::tolower(static_cast<unsigned char>(s[i++])));
  }
  return w;
}

}  // namespace

std::vector<BibEntry> parse_bibtex(std::string_view s, const std::string& source) {
  std::vector<BibEntry> out;
  std::size_t i = 0;
  auto fail = [&](const std::string& what) {
    throw InputError(fmt::format("{}: malformed BibTeX at character {}: {}", source, i, what));
  };
  while (true) {
    while (i < s.size() && space(s[i])) ++i;
    if (i == s.size()) break;
    const std::size_t start = i;
    if (s[i] != '@') fail("an entry must start with '@'");
    ++i;
    BibEntry e;
    e.type = word(s, i);
    if (e.type.empty() || i >= s.size() || s[i] != '{') fail("'@type{' expected");
    ++i;
    const std::size_t comma = s.find(',', i);
    if (comma == std::string_view::npos) fail("no ',' after the key");
    e.key = std::string(s.substr(i, comma - i));
    if (e.key.empty() || e.key.find_first_of(" \t\n{}") != std::string::npos)
      fail("a key expected");
    i = comma + 1;
    // Fields `name = {value}` or `name = "value"` or `name = 1994`, to the closing brace.
    int depth = 1;
    bool at_field = true;
    while (i < s.size() && depth > 0) {
      if (depth == 1 && at_field) {
        const std::string name = word(s, i);
        while (i < s.size() && space(s[i])) ++i;
        if (!name.empty()) {
          if (i >= s.size() || s[i] != '=') fail(fmt::format("'=' expected after {}", name));
          e.fields.push_back(name);
        }
        at_field = false;
        continue;
      }
      const char c = s[i++];
      if (c == '{') ++depth;
      if (c == '}') --depth;
      if (c == ',' && depth == 1) at_field = true;
    }
    if (depth != 0) fail(fmt::format("entry {}: braces do not balance", e.key));
    e.text = std::string(s.substr(start, i - start));
    out.push_back(std::move(e));
  }
  return out;
}

std::vector<Citation> registered_citations() {
  std::vector<Citation> out;
  auto add = [&](const char* group, const std::string& name, const std::string& bibtex) {
    const std::string who = fmt::format("{} {}", group, name);
    for (auto& e : parse_bibtex(bibtex, who)) {
      Citation* found = nullptr;
      for (auto& c : out) {
        if (c.entry.key == e.key) found = &c;
      }
      if (!found) {
        out.push_back({std::move(e), {who}});
      } else if (found->entry.text != e.text) {
        throw InputError(fmt::format("{} and {} cite '{}' with different entries", who,
                                     found->backs.front(), e.key));
      } else {
        found->backs.push_back(who);
      }
    }
  };
  for (const auto& t : transfer_list()) add("transfer", t.name, t.bibtex);
  for (const auto& k : kernel_list()) add("kernel", k.name, k.bibtex);
  for (const auto& m : model_list()) add("model", m.name, m.bibtex);
  return out;
}

std::string bibtex_listing() {
  std::string out;
  for (const auto& c : registered_citations()) {
    out += fmt::format("% {}\n{}\n\n", fmt::join(c.backs, ", "), c.entry.text);
  }
  return out;
}

}  // namespace mpmtb
