#include "system/run/output_folder.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "core/atomic_file.h"
#include "core/errors.h"

namespace cslam {

namespace fs = std::filesystem;

namespace {

// Files every cslam run writes, also those of versions before the manifest: a folder holding
// one of them is an earlier run's, whether or not it has a manifest.
constexpr const char* kRunOutputNames[] = {"camera_trajectory.txt", "metrics.json", "run.log",
                                           "clusters.csv", "config.yaml"};

std::vector<std::string> FilesUnder(const fs::path& dir) {
  std::vector<std::string> files;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec)) {
    if (!it->is_directory()) files.push_back(fs::relative(it->path(), dir).generic_string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

void WriteManifest(const fs::path& dir, const OutputManifest& m) {
  nlohmann::ordered_json j;
  j["cslam_outputs"] = 1;
  j["version"] = m.version;
  j["command"] = m.command;
  j["input"] = {{"path", m.input.path},
                {"kind", m.input.kind},
                {"cameras", m.input.cameras},
                {"max_frames", m.input.max_frames}};
  j["complete"] = m.complete;
  j["preexisting"] = m.preexisting;
  j["files"] = m.files;
  WriteFileAtomically((dir / kOutputManifestName).string(),
                      [&](std::ostream& o) { o << j.dump(1) << "\n"; });
}

// A path of the manifest that stays inside the folder: an edited manifest must not make
// --overwrite remove anything outside it.
bool InsideFolder(const std::string& rel) {
  const fs::path p(rel);
  if (p.empty() || p.is_absolute()) return false;
  return std::none_of(p.begin(), p.end(), [](const fs::path& part) { return part == ".."; });
}

void RemoveEarlierRun(const fs::path& dir, const OutputManifest& old) {
  std::vector<std::string> doomed = old.files;
  if (!old.complete) {
    // The run stopped before listing its files: everything but what was there before it.
    const std::set<std::string> keep(old.preexisting.begin(), old.preexisting.end());
    for (const std::string& f : FilesUnder(dir))
      if (!keep.count(f)) doomed.push_back(f);
  }
  doomed.push_back(kOutputManifestName);
  std::set<fs::path> parents;
  for (const std::string& rel : doomed) {
    if (!InsideFolder(rel)) continue;
    std::error_code ec;
    fs::remove(dir / rel, ec);
    if (ec) throw OutputError((dir / rel).string(), "cannot remove it: " + ec.message());
    for (fs::path p = fs::path(rel).parent_path(); !p.empty(); p = p.parent_path()) parents.insert(p);
  }
  // Deepest first, and only the ones left empty (a user's file keeps its folder).
  for (auto it = parents.rbegin(); it != parents.rend(); ++it) {
    std::error_code ec;
    if (fs::is_directory(dir / *it, ec) && fs::is_empty(dir / *it, ec)) fs::remove(dir / *it, ec);
  }
}

}  // namespace

OutputManifest ReadOutputManifest(const std::string& out_dir) {
  const fs::path path = fs::path(out_dir) / kOutputManifestName;
  std::ifstream in(path);
  if (!in) throw InputError(path.string(), "missing: not the output folder of a cslam run (or of a version before the manifest)");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
    OutputManifest m;
    if (!j.contains("cslam_outputs")) throw InputError(path.string(), "no 'cslam_outputs' key");
    m.version = j.value("version", "");
    m.command = j.value("command", "");
    const auto& input = j.at("input");
    m.input.path = input.at("path").get<std::string>();
    m.input.kind = input.at("kind").get<std::string>();
    m.input.cameras = input.value("cameras", "grey");
    m.input.max_frames = input.value("max_frames", 0);
    m.complete = j.at("complete").get<bool>();
    m.preexisting = j.value("preexisting", std::vector<std::string>{});
    m.files = j.value("files", std::vector<std::string>{});
    return m;
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path.string(), std::string("malformed: ") + e.what());
  }
}

void CreateWritableFolder(const std::string& out_dir) {
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec || !fs::is_directory(out_dir))
    throw OutputError(out_dir, "cannot create the output folder" + (ec ? ": " + ec.message() : ""));
  const fs::path probe = fs::path(out_dir) / ".cslam_write_test";
  {
    std::ofstream f(probe);
    if (!f) throw OutputError(out_dir, "the output folder is not writable");
  }
  fs::remove(probe, ec);
}

void PrepareOutputFolder(const std::string& out_dir, bool overwrite, OutputManifest manifest) {
  const fs::path dir(out_dir);
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw OutputError(out_dir, "cannot create the output folder: a file of that name exists");
  const bool has_manifest = fs::exists(dir / kOutputManifestName, ec);
  const bool has_outputs =
      has_manifest || std::any_of(std::begin(kRunOutputNames), std::end(kRunOutputNames),
                                  [&](const char* n) { return fs::exists(dir / n, ec); });
  const bool empty = !fs::exists(dir, ec) || fs::is_empty(dir, ec);
  if (has_outputs && !overwrite)
    throw ConfigError(out_dir + " holds the outputs of an earlier run; give --overwrite to "
                      "replace them (only the files that run wrote are removed) or choose "
                      "another --out");
  if (overwrite && !empty && !has_manifest)
    throw ConfigError(out_dir + " is not a cslam output folder (no " + kOutputManifestName +
                      (has_outputs ? "; written by a version before it" : "") +
                      "): --overwrite removes only what a cslam run wrote there, so it refuses; "
                      "delete the folder yourself or choose another --out");
  if (overwrite && has_manifest) RemoveEarlierRun(dir, ReadOutputManifest(out_dir));

  CreateWritableFolder(out_dir);
  manifest.complete = false;
  manifest.preexisting = FilesUnder(dir);
  manifest.files.clear();
  WriteManifest(dir, manifest);
}

void CompleteOutputManifest(const std::string& out_dir) {
  OutputManifest m = ReadOutputManifest(out_dir);
  const std::set<std::string> before(m.preexisting.begin(), m.preexisting.end());
  m.files.clear();
  for (const std::string& f : FilesUnder(out_dir))
    if (!before.count(f) && f != kOutputManifestName) m.files.push_back(f);
  m.complete = true;
  WriteManifest(out_dir, m);
}

}  // namespace cslam
