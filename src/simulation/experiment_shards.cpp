#include "breast_tumour_registration/simulation/experiment_shards.h"

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/strings.h"
#include "breast_tumour_registration/simulation/experiment_suite.h"

namespace btr {
namespace fs = std::filesystem;

ShardRange shard_range(size_t items, int k, int n) {
  if (n < 1 || k < 1 || k > n)
    throw InputError("shard " + std::to_string(k) + "/" + std::to_string(n) + ": expected 1 <= K <= N");
  ShardRange r;
  r.total = items;
  r.first = items * static_cast<size_t>(k - 1) / static_cast<size_t>(n);
  r.last = items * static_cast<size_t>(k) / static_cast<size_t>(n);
  return r;
}

void parse_shard(const std::string& text, int& k, int& n) {
  const size_t slash = text.find('/');
  const auto kk = slash == std::string::npos ? std::nullopt : parse_integer(std::string_view(text).substr(0, slash));
  const auto nn = slash == std::string::npos ? std::nullopt : parse_integer(std::string_view(text).substr(slash + 1));
  if (!kk || !nn) throw InputError("--shard '" + text + "': expected K/N, e.g. 3/8");
  shard_range(0, *kk, *nn);  // checks the bounds
  k = *kk;
  n = *nn;
}

std::string plan_fingerprint(const ExperimentSuiteOptions& opt, const std::vector<ExperimentRun>& runs,
                             const PhantomModel& model) {
  std::ostringstream s;
  s.precision(17);
  s << opt.preset << '|' << opt.poisson_ratio << '|' << opt.density << '|' << opt.rest_shape << '|'
    << model.rest.V.rows() << '|' << model.rest.T.rows() << '|' << opt.simulation_cell_size << '|'
    << to_string(opt.method_volume_form) << '|' << opt.method_nodal_element_share << '|' << opt.method_nodal_fallback << '|'
    << opt.method_stiffness_budget << '|'
    << (opt.method_unload_element_order == ElementOrder::Quadratic ? "quadratic unload|" : "")
    << (opt.truth_element_order == ElementOrder::Quadratic ? "quadratic truth|" : "")
    << (opt.given_configurations ? "given" : "generated") << '|';
  for (double e : opt.generating_youngs_moduli.empty() ? thesis_youngs_moduli() : opt.generating_youngs_moduli) s << e << ',';
  for (const auto& r : model.method_regions) s << '|' << r.name << ':' << r.label << ':' << r.relative_stiffness;
  for (const auto& r : runs) s << '|' << r.experiment << ':' << r.setting << ':' << r.variable << '=' << r.value;
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a
  for (unsigned char c : s.str()) {
    h ^= c;
    h *= 1099511628211ull;
  }
  char buf[24];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

void write_shard_info(const std::string& dir, int k, int n, const std::string& fingerprint) {
  std::ofstream out(fs::path(dir) / "shard.txt");
  if (!out) throw InputError("cannot write '" + (fs::path(dir) / "shard.txt").string() + "'");
  out << "shard " << k << " " << n << "\nplan " << fingerprint << "\n";
}

long merge_experiment_shards(const std::vector<std::string>& dirs, const std::string& out_csv) {
  if (dirs.empty()) throw InputError("merge: no shard folders given");
  std::map<int, std::string> by_index;
  int count = 0;
  std::string plan;
  for (const auto& d : dirs) {
    const fs::path info = fs::path(d) / "shard.txt";
    std::ifstream in(info);
    std::string word, fp;
    int k = 0, n = 0;
    if (!(in >> word >> k >> n) || word != "shard" || !(in >> word >> fp) || word != "plan")
      throw InputError("merge: '" + info.string() + "' is missing or not a shard file (btr_experiments --shard K/N writes it)");
    if (count == 0) {
      count = n;
      plan = fp;
    } else if (n != count || fp != plan) {
      throw InputError("merge: '" + d + "' is share " + std::to_string(k) + "/" + std::to_string(n) + " of plan " + fp +
                       ", the others of " + std::to_string(count) + " shares of plan " + plan + ": another study");
    }
    if (!by_index.emplace(k, d).second) throw InputError("merge: share " + std::to_string(k) + " given twice ('" + d + "')");
  }
  for (int k = 1; k <= count; ++k)
    if (!by_index.count(k)) throw InputError("merge: share " + std::to_string(k) + "/" + std::to_string(count) + " is missing");
  std::ofstream out(out_csv);
  if (!out) throw InputError("merge: cannot write '" + out_csv + "'");
  std::string header;
  long rows = 0;
  for (const auto& [k, d] : by_index) {
    const fs::path csv = fs::path(d) / "results.csv";
    std::ifstream in(csv);
    std::string line;
    if (!in || !std::getline(in, line)) throw InputError("merge: '" + csv.string() + "' is missing or empty");
    if (header.empty()) {
      header = line;
      out << header << '\n';
    } else if (line != header) {
      throw InputError("merge: '" + csv.string() + "' has another header than share 1");
    }
    while (std::getline(in, line))
      if (!line.empty()) {
        out << line << '\n';
        ++rows;
      }
  }
  return rows;
}

}  // namespace btr
