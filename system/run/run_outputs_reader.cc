#include "system/run/run_outputs_reader.h"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "core/errors.h"
#include "system/eval/trajectory_io.h"
#include "system/io/input_files.h"

namespace cslam {

namespace fs = std::filesystem;

namespace {

std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream s(line);
  for (std::string f; std::getline(s, f, ',');) fields.push_back(f);
  if (!line.empty() && line.back() == ',') fields.push_back("");
  return fields;
}

int ParseInt(const std::string& text, const std::string& file, int line, const std::string& name) {
  int value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (ec != std::errc() || ptr != end)
    throw InputError(file, line, "'" + name + "': expected an integer, got '" + text + "'");
  return value;
}

double ParseFinite(const std::string& text, const std::string& file, int line,
                   const std::string& name) {
  double value = 0.0;
  const char* begin = text.data();
  const char* end = text.data() + text.size();
  if (begin != end && *begin == '+') ++begin;
  const auto [ptr, ec] = std::from_chars(begin, end, value);
  if (ec != std::errc() || ptr != end || !std::isfinite(value))
    throw InputError(file, line, "'" + name + "': expected a finite number, got '" + text + "'");
  return value;
}

/// Calls `row(fields, line_number)` for each line after the header of a CSV file whose first
/// line must be `header` (a trailing '\r' is tolerated on every line).
template <typename RowFn>
void ForEachCsvRow(const std::string& file, const std::string& what, const std::string& header,
                   RowFn row) {
  std::ifstream in = OpenTextFile(file, what);
  std::string line;
  int number = 0;
  const size_t columns = SplitCsv(header).size();
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (number == 1) {
      if (line != header) throw InputError(file, 1, "expected the header '" + header + "'");
      continue;
    }
    if (line.empty()) continue;
    const auto fields = SplitCsv(line);
    if (fields.size() != columns)
      throw InputError(file, number,
                       "expected " + std::to_string(columns) + " comma-separated fields (" +
                           header + "), got " + std::to_string(fields.size()));
    row(fields, number);
  }
  if (in.bad()) throw InputError(file, "read error");
  if (number == 0) throw InputError(file, "expected the header '" + header + "', the file is empty");
}

Trajectory ReadRequiredKitti(const fs::path& file, const std::string& what) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec))
    throw InputError(file.string(), "missing: expected the " + what +
                                        " a finished 'cslam run' writes (is this its --out folder?)");
  return ReadTrajectory(file.string(), TrajectoryFormat::kKitti);
}

}  // namespace

RunOutputs ReadRunOutputs(const std::string& out_dir) {
  const fs::path out(out_dir);
  std::error_code ec;
  if (!fs::is_directory(out, ec))
    throw InputError(out_dir, "expected the output folder of a finished 'cslam run', found " +
                                  std::string(fs::exists(out, ec) ? "a file" : "nothing"));
  RunOutputs outputs;
  outputs.camera = ReadRequiredKitti(out / "camera_trajectory.txt", "camera trajectory");
  if (fs::exists(out / "camera_trajectory_gt.txt", ec))
    outputs.gt_camera =
        ReadTrajectory((out / "camera_trajectory_gt.txt").string(), TrajectoryFormat::kKitti);

  const std::string index = (out / "objects" / "index.csv").string();
  ForEachCsvRow(index, "cluster index", "cluster,first_frame,last_frame,frames,landmarks",
                [&](const std::vector<std::string>& f, int line) {
                  const int id = ParseInt(f[0], index, line, "cluster");
                  const int frames = ParseInt(f[3], index, line, "frames");
                  if (id < 1) throw InputError(index, line, "expected a moving cluster id >= 1");
                  if (outputs.clusters.count(id))
                    throw InputError(index, line, "cluster " + f[0] + " is listed twice");
                  const fs::path file = out / "objects" / (f[0] + ".txt");
                  Trajectory t = ReadRequiredKitti(file, "trajectory of cluster " + f[0]);
                  if (static_cast<int>(t.size()) != frames)
                    throw InputError(file.string(),
                                     "expected " + f[3] + " poses (" + index + " line " +
                                         std::to_string(line) + "), got " +
                                         std::to_string(t.size()));
                  outputs.clusters.emplace(id, std::move(t));
                });

  const std::string clusters = (out / "clusters.csv").string();
  ForEachCsvRow(clusters, "landmark clusters", "landmark,cluster,first_frame,last_frame,x,y,z",
                [&](const std::vector<std::string>& f, int line) {
                  RunLandmark l;
                  l.id = ParseInt(f[0], clusters, line, "landmark");
                  l.cluster = ParseInt(f[1], clusters, line, "cluster");
                  l.first_frame = ParseInt(f[2], clusters, line, "first_frame");
                  l.last_frame = ParseInt(f[3], clusters, line, "last_frame");
                  l.p_world = {ParseFinite(f[4], clusters, line, "x"),
                               ParseFinite(f[5], clusters, line, "y"),
                               ParseFinite(f[6], clusters, line, "z")};
                  if (l.cluster < -1)
                    throw InputError(clusters, line,
                                     "expected a cluster id >= -1 (0: static, -1: outlier)");
                  if (l.cluster >= 1 && !outputs.clusters.count(l.cluster))
                    throw InputError(clusters, line,
                                     "cluster " + f[1] + " has no trajectory in " + index);
                  outputs.landmarks.push_back(l);
                });

  // The labelled objects' truth: written only for inputs that have it.
  const std::string gt_index = (out / "objects_gt" / "index.csv").string();
  if (fs::exists(gt_index, ec))
    ForEachCsvRow(gt_index, "ground-truth object index", "gt_object,type,first_frame,last_frame,frames,cluster,length,width,height",
                  [&](const std::vector<std::string>& f, int line) {
                    const int id = ParseInt(f[0], gt_index, line, "gt_object");
                    const fs::path file = out / "objects_gt" / (f[0] + ".txt");
                    outputs.gt_objects[id] = ReadRequiredKitti(file, "true trajectory of object " + f[0]);
                    outputs.gt_object_match[id] = {f[1], ParseInt(f[5], gt_index, line, "cluster")};
                    outputs.gt_object_size[id] = {ParseFinite(f[6], gt_index, line, "length"),
                                                  ParseFinite(f[7], gt_index, line, "width"),
                                                  ParseFinite(f[8], gt_index, line, "height")};
                  });

  // The final-state overlays' keypoints: written only for runs on images.
  const fs::path keypoints = out / "overlay_keypoints.csv";
  if (fs::exists(keypoints, ec)) {
    const std::string file = keypoints.string();
    ForEachCsvRow(file, "overlay keypoints", "frame,landmark,step,u,v",
                  [&](const std::vector<std::string>& f, int line) {
                    const int frame = ParseInt(f[0], file, line, "frame");
                    const int landmark = ParseInt(f[1], file, line, "landmark");
                    const int step = ParseInt(f[2], file, line, "step");
                    std::vector<RunKeypoint>& at = outputs.keypoints[frame];
                    if (step == 0) at.push_back({landmark, {}});
                    if (at.empty() || at.back().landmark != landmark ||
                        static_cast<int>(at.back().trail.size()) != step)
                      throw InputError(file, line, "expected step " +
                                                       std::to_string(at.empty() ? 0 : at.back().trail.size()) +
                                                       " of landmark " + f[1] + "'s trail");
                    at.back().trail.emplace_back(ParseFinite(f[3], file, line, "u"),
                                                 ParseFinite(f[4], file, line, "v"));
                  });
  }
  return outputs;
}

}  // namespace cslam
