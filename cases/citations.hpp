// The papers behind the registered variants: each transfer, kernel and model
// carries its BibTeX in its own header (`bibtex`); `mpmtb list --bibtex`
// prints every entry once, with the variants it backs.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace mpmtb {

struct BibEntry {
  std::string type;                 // article, book, inproceedings, ...
  std::string key;                  // the citation key
  std::vector<std::string> fields;  // field names, lower case, in order
  std::string text;                 // the whole entry, '@' to its closing brace
};

// Splits BibTeX text into its entries. Throws InputError naming `source` when
// an entry lacks '@', a type, a key or a closing brace, or braces do not balance.
std::vector<BibEntry> parse_bibtex(std::string_view text, const std::string& source);

struct Citation {
  BibEntry entry;
  std::vector<std::string> backs;  // "transfer pic", "kernel linear", ...
};

// Every registered variant's entries, each key once (in registry order). Two
// variants citing one key must carry the same text, else InputError.
std::vector<Citation> registered_citations();

// The text of `mpmtb list --bibtex`.
std::string bibtex_listing();

}  // namespace mpmtb
