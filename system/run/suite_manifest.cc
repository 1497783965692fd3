#include "system/run/suite_manifest.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>

#include "core/errors.h"
#include "system/datasets/dataset.h"
#include "system/synthetic/synthetic_io.h"
#include "system/synthetic/synthetic_scene.h"

namespace cslam {

namespace fs = std::filesystem;

namespace {

// Reads one manifest: every message is "FILE:LINE: entry NAME: what".
class ManifestParser {
 public:
  explicit ManifestParser(std::string file) : file_(std::move(file)), dir_(fs::path(file_).parent_path()) {}

  [[noreturn]] void Fail(const YAML::Node& node, const std::string& entry, const std::string& what) const {
    std::string where = file_;
    if (node.IsDefined() && node.Mark().line >= 0) where += ":" + std::to_string(node.Mark().line + 1);
    throw ConfigError(where + ": " + (entry.empty() ? "" : "entry '" + entry + "': ") + what);
  }

  void CheckKeys(const YAML::Node& map, const std::set<std::string>& known, const std::string& entry,
                 const std::string& what) const {
    if (!map.IsMap()) Fail(map, entry, what + " must be a mapping");
    for (const auto& kv : map) {
      const std::string key = kv.first.as<std::string>();
      if (!known.count(key)) {
        std::string list;
        for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
        Fail(kv.first, entry, "unknown key '" + key + "' in " + what + " (known: " + list + ")");
      }
    }
  }

  std::string String(const YAML::Node& node, const std::string& entry, const std::string& key) const {
    if (!node.IsScalar()) Fail(node, entry, "'" + key + "' must be a single value");
    return node.as<std::string>();
  }

  int Int(const YAML::Node& node, const std::string& entry, const std::string& key, int min) const {
    int v = 0;
    if (!node.IsScalar() || !YAML::convert<int>::decode(node, v))
      Fail(node, entry, "'" + key + "' must be an integer");
    if (v < min) Fail(node, entry, "'" + key + "' must be >= " + std::to_string(min));
    return v;
  }

  std::string Path(const YAML::Node& node, const std::string& entry, const std::string& key) const {
    const fs::path p(String(node, entry, key));
    return (p.is_absolute() ? p : dir_ / p).lexically_normal().string();
  }

  std::string ExistingFolder(const YAML::Node& node, const std::string& entry,
                             const std::string& key) const {
    const std::string path = Path(node, entry, key);
    std::error_code ec;
    if (!fs::exists(path, ec)) Fail(node, entry, "'" + key + "': " + path + " does not exist");
    if (!fs::is_directory(path, ec)) Fail(node, entry, "'" + key + "': " + path + " is not a folder");
    if (DetectDataset(path) == DatasetKind::kUnknown)
      Fail(node, entry, "'" + key + "': " + path +
                            " is of no known kind (expected a KITTI raw drive with image_00/, a "
                            "KITTI odometry sequence with image_0/ and calib.txt, or a synthetic "
                            "sequence with observations.csv)");
    return path;
  }

  std::string ExistingFile(const YAML::Node& node, const std::string& entry,
                           const std::string& key) const {
    const std::string path = Path(node, entry, key);
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) Fail(node, entry, "'" + key + "': " + path + " is not a file");
    return path;
  }

  SuiteSynthetic Synthetic(const YAML::Node& node, const std::string& entry) const {
    CheckKeys(node, {"preset", "seed", "frames"}, entry, "'synthetic'");
    SuiteSynthetic s;
    if (node["preset"]) s.preset = String(node["preset"], entry, "preset");
    if (s.preset != "indoor" && s.preset != "outdoor")
      Fail(node["preset"], entry, "'preset' must be indoor or outdoor, got '" + s.preset + "'");
    if (node["seed"]) s.seed = Int(node["seed"], entry, "seed", 0);
    if (node["frames"]) s.frames = Int(node["frames"], entry, "frames", 0);
    if (s.frames == 1) Fail(node["frames"], entry, "'frames' must be 0 (the preset's) or >= 2");
    return s;
  }

  std::string file_;
  fs::path dir_;
};

// The settings a run takes; a grid lists several values of each.
struct RunSettings {
  std::string config, method, ablation, mode, cameras;
};

std::string SystemLabel(const RunSettings& s) {
  std::string label = s.method.empty() ? "clusterslam" : s.method;
  if (!s.ablation.empty() && s.ablation != "none") label += "/" + s.ablation;
  if (!s.config.empty()) label += "@" + fs::path(s.config).stem().string();
  if (!s.mode.empty()) label += "," + s.mode;
  if (!s.cameras.empty()) label += "," + s.cameras;
  return label;
}

std::string Sanitize(std::string s) {
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.') c = '_';
  return s;
}

}  // namespace

std::string SuiteSynthetic::Name() const {
  return "synthetic_" + preset + "_seed" + std::to_string(seed) +
         (frames > 0 ? "_f" + std::to_string(frames) : "");
}

void SuiteSlurmOptions::Check() const {
  if (cpus_per_task < 0) throw ConfigError("slurm.cpus_per_task: must be >= 0, got " + std::to_string(cpus_per_task));
  for (const std::string* v : {&partition, &time, &mem, &account})
    if (v->find_first_of(" \t\n'\"") != std::string::npos)
      throw ConfigError("slurm: '" + *v + "' may not hold spaces or quotes");
}

std::vector<std::string> SuiteRun::RunArguments(const std::string& input_folder,
                                                const std::string& out) const {
  std::vector<std::string> a = {"run", input_folder, "--out", out, "--no-progress"};
  if (!config.empty()) a.insert(a.end(), {"--config", config});
  if (!method.empty()) a.insert(a.end(), {"--method", method});
  if (!ablation.empty()) a.insert(a.end(), {"--ablation", ablation});
  if (!mode.empty()) a.insert(a.end(), {"--mode", mode});
  if (!cameras.empty()) a.insert(a.end(), {"--cameras", cameras});
  if (max_frames > 0) a.insert(a.end(), {"--max-frames", std::to_string(max_frames)});
  return a;
}

SuiteManifest ReadSuiteManifest(const std::string& file) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec))
    throw ConfigError(file + ": the suite manifest does not exist or is not a file");
  SuiteManifest m;
  m.file = fs::absolute(file).lexically_normal().string();
  const ManifestParser p(m.file);
  YAML::Node root;
  try {
    root = YAML::LoadFile(m.file);
  } catch (const YAML::Exception& e) {
    throw ConfigError(m.file + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg);
  }
  if (!root.IsMap()) throw ConfigError(m.file + ": a suite manifest is a mapping with 'entries:'");
  p.CheckKeys(root, {"entries", "defaults", "slurm"}, "", "the manifest");

  if (const YAML::Node s = root["slurm"]) {
    p.CheckKeys(s, {"partition", "time", "mem", "cpus_per_task", "account"}, "", "'slurm'");
    if (s["partition"]) m.slurm.partition = p.String(s["partition"], "", "partition");
    if (s["time"]) m.slurm.time = p.String(s["time"], "", "time");
    if (s["mem"]) m.slurm.mem = p.String(s["mem"], "", "mem");
    if (s["account"]) m.slurm.account = p.String(s["account"], "", "account");
    if (s["cpus_per_task"]) m.slurm.cpus_per_task = p.Int(s["cpus_per_task"], "", "cpus_per_task", 0);
    try {
      m.slurm.Check();
    } catch (const ConfigError& e) {
      p.Fail(s, "", e.what());
    }
  }

  // The pair of a KITTI raw drive, spelt as `cslam run --cameras` spells it.
  const auto cameras = [&](const YAML::Node& n, const std::string& who) {
    const std::string v = p.String(n, who, "cameras");
    if (v != "grey" && v != "color") p.Fail(n, who, "'cameras' must be grey or color, got '" + v + "'");
    return v;
  };
  RunSettings defaults;
  int default_max_frames = 0;
  if (const YAML::Node d = root["defaults"]) {
    p.CheckKeys(d, {"config", "method", "ablation", "mode", "cameras", "max_frames"}, "", "'defaults'");
    if (d["config"]) defaults.config = p.ExistingFile(d["config"], "", "config");
    if (d["method"]) defaults.method = p.String(d["method"], "", "method");
    if (d["ablation"]) defaults.ablation = p.String(d["ablation"], "", "ablation");
    if (d["mode"]) defaults.mode = p.String(d["mode"], "", "mode");
    if (d["cameras"]) defaults.cameras = cameras(d["cameras"], "");
    if (d["max_frames"]) default_max_frames = p.Int(d["max_frames"], "", "max_frames", 0);
  }

  const YAML::Node entries = root["entries"];
  if (!entries || !entries.IsSequence() || entries.size() == 0)
    p.Fail(entries ? entries : root, "", "'entries' must be a non-empty list");

  std::map<std::string, int> id_lines;
  auto claim_id = [&](const std::string& id, const YAML::Node& node, const std::string& entry) {
    const auto [it, fresh] = id_lines.emplace(id, node.Mark().line + 1);
    if (!fresh)
      p.Fail(node, entry, "run name '" + id + "' is already used by the entry at line " +
                              std::to_string(it->second) + " (give each entry its own 'name')");
  };

  for (size_t i = 0; i < entries.size(); ++i) {
    const YAML::Node e = entries[i];
    std::string label = "#" + std::to_string(i + 1);
    if (e.IsMap() && e["name"] && e["name"].IsScalar()) label = e["name"].as<std::string>();
    p.CheckKeys(e,
                {"name", "input", "synthetic", "config", "method", "ablation", "mode", "cameras", "max_frames",
                 "grid", "trajectory", "format", "frames", "system"},
                label, "an entry");
    std::string name = e["name"] ? Sanitize(p.String(e["name"], label, "name")) : "";
    const std::string who = name.empty() ? label : name;
    if (bool(e["input"]) == bool(e["synthetic"]))
      p.Fail(e, who, "give exactly one of 'input' (a dataset folder) or 'synthetic' (preset, seed)");
    std::string input, drive;
    std::optional<SuiteSynthetic> synthetic;
    if (e["input"]) {
      input = p.ExistingFolder(e["input"], who, "input");
      drive = fs::path(input).filename().string();
    } else {
      synthetic = p.Synthetic(e["synthetic"], who);
      drive = synthetic->Name();
    }
    if (name.empty()) name = Sanitize(drive);
    const int max_frames =
        e["max_frames"] ? p.Int(e["max_frames"], who, "max_frames", 0) : default_max_frames;
    const int line = e.Mark().line + 1;

    if (e["trajectory"]) {
      for (const char* k : {"config", "method", "ablation", "mode", "cameras", "grid"})
        if (e[k]) p.Fail(e[k], who, std::string("'") + k + "' does not apply to an external 'trajectory' entry");
      if (!e["system"]) p.Fail(e, who, "an external 'trajectory' entry needs 'system' (its name in the table)");
      SuiteExternal x;
      x.entry = name;
      x.line = line;
      x.drive = drive;
      x.input = input;
      x.synthetic = synthetic;
      x.max_frames = max_frames;
      x.trajectory = p.ExistingFile(e["trajectory"], who, "trajectory");
      if (e["format"]) {
        x.format = p.String(e["format"], who, "format");
        if (x.format != "kitti" && x.format != "tum")
          p.Fail(e["format"], who, "'format' must be kitti or tum, got '" + x.format + "'");
      }
      if (e["frames"]) x.frames = p.ExistingFile(e["frames"], who, "frames");
      x.system = p.String(e["system"], who, "system");
      x.id = name;
      claim_id(x.id, e, who);
      m.externals.push_back(x);
      continue;
    }
    for (const char* k : {"format", "frames"})
      if (e[k]) p.Fail(e[k], who, std::string("'") + k + "' applies only to an external 'trajectory' entry");

    RunSettings base = defaults;
    if (e["config"]) base.config = p.ExistingFile(e["config"], who, "config");
    if (e["method"]) base.method = p.String(e["method"], who, "method");
    if (e["ablation"]) base.ablation = p.String(e["ablation"], who, "ablation");
    if (e["mode"]) base.mode = p.String(e["mode"], who, "mode");
    if (e["cameras"]) base.cameras = cameras(e["cameras"], who);

    // The grid: every combination of the listed values, in the order written.
    std::vector<RunSettings> settings = {base};
    std::vector<std::string> suffixes = {""};
    if (const YAML::Node g = e["grid"]) {
      p.CheckKeys(g, {"config", "method", "ablation", "mode"}, who, "'grid'");
      for (const auto& kv : g) {
        const std::string key = kv.first.as<std::string>();
        const YAML::Node values = kv.second;
        if (!values.IsSequence() || values.size() == 0)
          p.Fail(values, who, "grid '" + key + "' must be a non-empty list");
        std::vector<RunSettings> next;
        std::vector<std::string> next_suffixes;
        for (size_t s = 0; s < settings.size(); ++s)
          for (const YAML::Node& v : values) {
            RunSettings r = settings[s];
            std::string value;
            if (key == "config") {
              r.config = p.ExistingFile(v, who, "grid config");
              value = fs::path(r.config).stem().string();
            } else {
              value = p.String(v, who, "grid " + key);
              (key == "method" ? r.method : key == "ablation" ? r.ablation : r.mode) = value;
            }
            next.push_back(r);
            next_suffixes.push_back(suffixes[s] + "-" + Sanitize(value));
          }
        settings = std::move(next);
        suffixes = std::move(next_suffixes);
      }
    }
    for (size_t s = 0; s < settings.size(); ++s) {
      SuiteRun r;
      r.entry = name;
      r.line = line;
      r.drive = drive;
      r.input = input;
      r.synthetic = synthetic;
      r.config = settings[s].config;
      r.method = settings[s].method;
      r.ablation = settings[s].ablation;
      r.mode = settings[s].mode;
      r.cameras = settings[s].cameras;
      r.max_frames = max_frames;
      r.system = e["system"] && settings.size() == 1 ? p.String(e["system"], who, "system")
                                                     : SystemLabel(settings[s]);
      r.id = name + suffixes[s];
      claim_id(r.id, e, who);
      m.runs.push_back(r);
    }
  }
  return m;
}

std::string SyntheticInputFolder(const std::string& suite_out, const SuiteSynthetic& synthetic) {
  return (fs::absolute(suite_out) / "inputs" / synthetic.Name()).lexically_normal().string();
}

void PrepareSyntheticInputs(SuiteManifest& manifest, const std::string& suite_out) {
  auto prepare = [&](const SuiteSynthetic& s) {
    const std::string dir = SyntheticInputFolder(suite_out, s);
    if (DetectDataset(dir) == DatasetKind::kSynthetic) return dir;
    SyntheticOptions o;
    o.preset = s.preset;
    o.seed = s.seed;
    o.frames = s.frames;
    o.Check();
    // Written beside and renamed, so an interrupted generation never looks complete.
    const std::string tmp = dir + ".partial";
    std::error_code ec;
    fs::remove_all(tmp, ec);
    WriteSynthetic(GenerateSynthetic(o), tmp);
    fs::remove_all(dir, ec);
    fs::rename(tmp, dir, ec);
    if (ec) throw OutputError(dir, "cannot move the generated sequence into place: " + ec.message());
    return dir;
  };
  for (SuiteRun& r : manifest.runs)
    if (r.synthetic) r.input = prepare(*r.synthetic);
  for (SuiteExternal& x : manifest.externals)
    if (x.synthetic) x.input = prepare(*x.synthetic);
}

}  // namespace cslam
