// The text of a comparison and the `mpmtb compare` subcommand.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "compare/compare.hpp"

namespace mpmtb::compare {
namespace {

std::string relative(double r) {
  return std::isnan(r) ? "-" : fmt::format("{:+.3g}", r);
}

// Columns padded to their widest cell.
std::string table(const std::vector<std::vector<std::string>>& rows) {
  std::vector<std::size_t> width;
  for (const auto& r : rows) {
    width.resize(std::max(width.size(), r.size()));
    for (std::size_t i = 0; i < r.size(); ++i) width[i] = std::max(width[i], r[i].size());
  }
  std::string out;
  for (const auto& r : rows) {
    std::string line;
    for (std::size_t i = 0; i < r.size(); ++i) {
      line += i + 1 < r.size() ? fmt::format("{:<{}}  ", r[i], width[i]) : r[i];
    }
    out += line + "\n";
  }
  return out;
}

// The metric a change belongs to, without the row key of a table.
std::string metric_name(const Change& c) {
  const auto colon = c.metric.rfind(": ");
  return colon == std::string::npos ? c.metric : c.metric.substr(colon + 2);
}

}  // namespace

std::string render(const Report& report, const std::string& old_name, const std::string& new_name,
                   std::size_t limit) {
  std::string out;
  if (!report.changes.empty()) {
    std::vector<std::vector<std::string>> rows = {
        {"file", "metric", "old", "new", "rel diff", "tolerance"}};
    for (const auto& c : report.changes) {
      if (limit && rows.size() > limit) break;
      rows.push_back(
          {c.file, c.metric, c.old_value, c.new_value, relative(c.rel_diff), c.tolerance});
    }
    out += table(rows);
    if (limit && report.changes.size() > limit) {
      out += fmt::format("... and {} more (--limit 0 prints every one)\n",
                         report.changes.size() - limit);
    }
    std::map<std::string, int> by_metric;
    for (const auto& c : report.changes) ++by_metric[metric_name(c)];
    out += "changed metrics:";
    for (const auto& [m, n] : by_metric) out += fmt::format(" {} ({})", m, n);
    out += "\n";
  }
  for (const auto& f : report.only_old) out += fmt::format("only in {}: {}\n", old_name, f);
  for (const auto& f : report.only_new) out += fmt::format("only in {}: {}\n", new_name, f);
  // Timings: the spread of new/old per metric, for the record only.
  std::map<std::string, std::vector<double>> ratios;
  for (const auto& t : report.timings) {
    if (t.old_value > 0 && t.new_value > 0) ratios[t.metric].push_back(t.new_value / t.old_value);
  }
  for (auto& [m, r] : ratios) {
    std::sort(r.begin(), r.end());
    out += fmt::format(
        "timing {} (never failed): {} values, new/old median {:.3g}, range {:.3g} to {:.3g}\n", m,
        r.size(), r[r.size() / 2], r.front(), r.back());
  }
  out += fmt::format(
      "{} files and {} values compared: {} changed beyond tolerance, {} files only in {}, {} only "
      "in {}\n",
      report.files, report.values, report.changes.size(), report.only_old.size(), old_name,
      report.only_new.size(), new_name);
  return out;
}

int command_compare(const CompareRequest& request) {
  const Tolerances tolerances =
      request.tolerances.empty() ? Tolerances::builtin() : Tolerances::load(request.tolerances);
  const Report report = compare_paths(request.old_root, request.new_root, tolerances);
  fmt::print("{}", render(report, request.old_root, request.new_root, request.limit));
  return report.changed() ? 1 : 0;
}

}  // namespace mpmtb::compare
