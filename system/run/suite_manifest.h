#pragma once
// The manifest of `cslam bench --suite FILE.yaml` (docs/usage.md "Benchmark suites"): which
// inputs to run, with which configurations, and which external trajectories to score against
// the same ground truth. Reading it expands every grid into single runs, resolves every path
// relative to the manifest file, and checks everything that can be checked before a run
// starts: unknown keys, missing folders, folders of no known kind, duplicate run names.
#include <optional>
#include <string>
#include <vector>

namespace cslam {

/// A generated synthetic sequence named by preset and seed (`cslam synth`).
struct SuiteSynthetic {
  std::string preset = "outdoor";  ///< indoor | outdoor
  int seed = 1;
  int frames = 0;                  ///< 0: the preset draws the length
  /// Folder name of the generated sequence, e.g. "synthetic_outdoor_seed1_f40".
  std::string Name() const;
};

/// Resources of one Slurm array task; empty / 0 = not requested (the cluster's default).
struct SuiteSlurmOptions {
  std::string partition;
  std::string time;     ///< sbatch --time, e.g. "01:00:00"
  std::string mem;      ///< sbatch --mem, e.g. "4G"
  int cpus_per_task = 0;
  std::string account;
  /// Throws ConfigError naming the key and the rule.
  void Check() const;
};

/// One `cslam run` of the suite: an input with one configuration.
struct SuiteRun {
  std::string id;      ///< unique; its output folder is <suite out>/runs/<id>
  std::string entry;   ///< the manifest entry's name
  int line = 0;        ///< the entry's line in the manifest
  std::string drive;   ///< the input's name: the table's and the chart's "drive"
  std::string input;   ///< absolute input folder ("" for a synthetic entry until generated)
  std::optional<SuiteSynthetic> synthetic;
  std::string config;  ///< absolute YAML path or ""
  std::string method, ablation, mode;  ///< "" = cslam run's default
  std::string cameras;  ///< KITTI raw: "grey" or "color" (cslam run --cameras); "" = its default
  int max_frames = 0;
  std::string system;  ///< the group label: method[/ablation][@config][,mode] or `system:`

  /// The arguments of the child process after the program path:
  /// run INPUT --out OUT --no-progress [--config ..] [--method ..] ...
  std::vector<std::string> RunArguments(const std::string& input_folder,
                                        const std::string& out) const;
};

/// Another system's camera trajectory, scored against the ground truth of `input`.
struct SuiteExternal {
  std::string id;
  std::string entry;
  int line = 0;
  std::string drive;
  std::string input;   ///< absolute folder holding the ground truth ("" when synthetic)
  std::optional<SuiteSynthetic> synthetic;
  int max_frames = 0;
  std::string trajectory;  ///< absolute path of the file
  std::string format;      ///< "kitti" | "tum" | "" (guessed from the first line)
  std::string frames;      ///< absolute path of a frames list (one frame index a line) or ""
  std::string system;      ///< the group label (required)
};

/// A read manifest.
struct SuiteManifest {
  std::string file;  ///< absolute path of the manifest
  std::vector<SuiteRun> runs;
  std::vector<SuiteExternal> externals;
  SuiteSlurmOptions slurm;
};

/// Reads and checks a manifest. Throws ConfigError naming the file, the line and the entry:
/// YAML syntax, unknown keys, a wrong type, an entry with no or two inputs, a missing folder
/// or file, a folder of no known kind, a grid key with no values, duplicate run ids.
SuiteManifest ReadSuiteManifest(const std::string& file);

/// Where a synthetic sequence is generated inside a suite's output folder.
std::string SyntheticInputFolder(const std::string& suite_out, const SuiteSynthetic& synthetic);

/// Generates (once) every synthetic sequence the manifest names into `suite_out`/inputs and
/// fills the runs' and externals' `input`. A sequence already there is reused.
void PrepareSyntheticInputs(SuiteManifest& manifest, const std::string& suite_out);

}  // namespace cslam
