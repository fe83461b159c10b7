// Studies bigger than one machine: the experiment suite's plan cut into N deterministic shares
// (contiguous blocks of its (generating modulus, run) items, so that a share simulates only
// the moduli it needs), each run anywhere (`btr_experiments --shard K/N`: a GNU parallel line
// or a Slurm job array, see bench/slurm_experiments.sh), and the shares' CSVs joined back in
// plan order. Each share's folder holds results.csv and shard.txt, which names the share and
// a fingerprint of the plan, so that shares of different studies are never joined.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace btr {

struct ExperimentSuiteOptions;
struct PhantomModel;
struct ExperimentRun;

struct ShardRange {
  size_t first = 0, last = 0;  ///< items [first, last) of `total`
  size_t total = 0;
};

/// Share k (1-based) of n of `items`. Throws InputError unless 1 <= k <= n.
ShardRange shard_range(size_t items, int k, int n);

/// Parses "K/N" (e.g. "3/8"). Throws InputError naming the expected form.
void parse_shard(const std::string& text, int& k, int& n);

/// A fingerprint of the study: the runs, the moduli, the preset and options, and the model's size
/// and tissue regions.
std::string plan_fingerprint(const ExperimentSuiteOptions& opt, const std::vector<ExperimentRun>& runs,
                             const PhantomModel& model);

/// Writes dir/shard.txt for share k of n.
void write_shard_info(const std::string& dir, int k, int n, const std::string& fingerprint);

/// Joins the shares in `dirs` (any order) into `out_csv`: checks that they are shares 1..N of
/// one study, each once, with one header; rows in plan order. Returns the rows written.
/// Throws InputError naming the folder at fault.
long merge_experiment_shards(const std::vector<std::string>& dirs, const std::string& out_csv);

}  // namespace btr
