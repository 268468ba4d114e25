// A small RFC 4180 reader for the result tables that `mpmtb compare` pairs.
#pragma once

#include <string>
#include <vector>

namespace mpmtb::compare {

struct CsvText {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;  // each as long as the header
};

// Fields may be quoted ("a,b", "say ""hi"""); a quote left open, or a row with
// another number of fields than the header, throws InputError naming `source`.
CsvText parse_csv(const std::string& text, const std::string& source);

}  // namespace mpmtb::compare
