#pragma once
// A run's output folder and its manifest, OUT/cslam_outputs.json: what the run was given (the
// input, so `cslam render` can find the images again) and every file the run wrote. A new run
// refuses a folder holding an earlier run's outputs, since files of the old run (an object id
// the new run does not have, an overlay of another frame) would sit beside the new ones
// looking like its own; `--overwrite` removes exactly the files the manifest lists and nothing
// a user put there.
#include <string>
#include <vector>

namespace cslam {

/// The manifest's file name inside a run's output folder.
inline constexpr const char* kOutputManifestName = "cslam_outputs.json";

/// What a run was pointed at: enough to open the same input again.
struct RecordedInput {
  std::string path;      ///< absolute path of the input folder
  std::string kind;      ///< kInputKindNames word
  std::string cameras;   ///< "grey" or "color" (KITTI raw)
  int max_frames = 0;    ///< 0 = all
};

/// The contents of cslam_outputs.json.
struct OutputManifest {
  std::string version;            ///< VersionString() of the writer
  std::string command;            ///< "run", "demo"
  RecordedInput input;
  /// false while the run goes on: a crashed run leaves it so, and `--overwrite` then removes
  /// every file but `preexisting`.
  bool complete = false;
  std::vector<std::string> preexisting;  ///< files in the folder before the run (not ours)
  std::vector<std::string> files;        ///< files the run wrote, relative to the folder
};

/// Reads OUT/cslam_outputs.json. Throws InputError naming the file when it is missing or
/// malformed.
OutputManifest ReadOutputManifest(const std::string& out_dir);

/// Creates `out_dir` (and its parents) and checks it is writable; throws OutputError naming it
/// otherwise.
void CreateWritableFolder(const std::string& out_dir);

/// Makes `out_dir` ready for a new run and writes its manifest (complete = false):
/// - missing or empty: created;
/// - holding an earlier run's outputs (a manifest, or files a cslam run writes): refused with
///   ConfigError unless `overwrite`; with it, the files of the manifest are removed (all but
///   its `preexisting` ones when that run did not finish), then the folders left empty;
/// - holding other files only: kept, recorded as preexisting; `overwrite` is refused there
///   (ConfigError: not a cslam output folder), so it can never remove a user's files.
/// Throws OutputError when the folder cannot be created or written.
void PrepareOutputFolder(const std::string& out_dir, bool overwrite, OutputManifest manifest);

/// Completes the manifest: every file now in `out_dir` that was not preexisting is listed as
/// written. Throws OutputError when it cannot be written.
void CompleteOutputManifest(const std::string& out_dir);

}  // namespace cslam
