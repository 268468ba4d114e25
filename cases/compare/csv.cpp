#include "compare/csv.hpp"

#include <fmt/format.h>

#include "core/errors.hpp"

namespace mpmtb::compare {

CsvText parse_csv(const std::string& text, const std::string& source) {
  std::vector<std::vector<std::string>> records;
  std::vector<std::string> record;
  std::string field;
  bool quoted = false, any = false;
  auto end_record = [&] {
    record.push_back(std::move(field));
    field.clear();
    records.push_back(std::move(record));
    record.clear();
    any = false;
  };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') {
        field += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        field += c;
      }
      continue;
    }
    if (c == '"') {
      quoted = any = true;
    } else if (c == ',') {
      record.push_back(std::move(field));
      field.clear();
      any = true;
    } else if (c == '\n') {
      end_record();
    } else if (c != '\r') {
      field += c;
      any = true;
    }
  }
  if (quoted) throw InputError(fmt::format("{}: malformed CSV: a quote is not closed", source));
  if (any || !record.empty()) end_record();
  if (records.empty()) throw InputError(fmt::format("{}: malformed CSV: no header", source));
  CsvText out;
  out.header = std::move(records.front());
  for (std::size_t r = 1; r < records.size(); ++r) {
    if (records[r].size() != out.header.size()) {
      throw InputError(fmt::format("{}: malformed CSV: row {} has {} fields, the header {}", source,
                                   r + 1, records[r].size(), out.header.size()));
    }
    out.rows.push_back(std::move(records[r]));
  }
  return out;
}

}  // namespace mpmtb::compare
