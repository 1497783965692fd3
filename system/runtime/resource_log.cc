#include "system/runtime/resource_log.h"

#include <sys/resource.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <iomanip>

#include "core/atomic_file.h"
#include "core/errors.h"

namespace cslam {

double ResidentMegabytes() {
  std::ifstream statm("/proc/self/statm");
  long long size_pages = 0, resident_pages = 0;
  if (!(statm >> size_pages >> resident_pages)) return 0.0;
  return static_cast<double>(resident_pages) * static_cast<double>(sysconf(_SC_PAGESIZE)) /
         (1024.0 * 1024.0);
}

double PeakResidentMegabytes() {
  struct rusage usage {};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0.0;
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

void ResourceSampler::AfterFrame(int frames_done) {
  if (every_ <= 0 || frames_done % every_ != 0) return;
  samples_.push_back({frames_done, timer_.ElapsedS(), ResidentMegabytes()});
}

void ResourceSampler::Finish(int frames_done) {
  if (!samples_.empty() && samples_.back().frame == frames_done) return;
  samples_.push_back({frames_done, timer_.ElapsedS(), ResidentMegabytes()});
}

std::vector<double> FramesPerSecond(const std::vector<ResourceSample>& samples) {
  std::vector<double> fps;
  for (size_t i = 1; i < samples.size(); ++i) {
    const double dt = samples[i].elapsed_s - samples[i - 1].elapsed_s;
    fps.push_back(dt > 0 ? (samples[i].frame - samples[i - 1].frame) / dt : 0.0);
  }
  return fps;
}

void WriteResourceLog(const std::vector<ResourceSample>& samples, const std::string& out_dir) {
  if (samples.size() < 2) return;
  namespace fs = std::filesystem;
  const fs::path out(out_dir);
  const std::vector<double> fps = FramesPerSecond(samples);
  WriteFileAtomically((out / "resources.csv").string(), [&](std::ostream& o) {
    o << "frame,elapsed_s,rss_mb,fps\n" << std::fixed;
    for (size_t i = 0; i < samples.size(); ++i) {
      o << samples[i].frame << "," << std::setprecision(3) << samples[i].elapsed_s << ","
        << std::setprecision(1) << samples[i].rss_mb << ",";
      if (i > 0) o << std::setprecision(2) << fps[i - 1];
      o << "\n";
    }
  });
}

std::vector<ResourceSample> ReadResourceLog(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, 0, "cannot open the file");
  std::vector<ResourceSample> samples;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line_no == 1) {
      if (line != "frame,elapsed_s,rss_mb,fps")
        throw InputError(path, 1, "expected the header 'frame,elapsed_s,rss_mb,fps'");
      continue;
    }
    if (line.empty()) continue;
    std::istringstream fields(line);
    ResourceSample s;
    char c1 = 0, c2 = 0;
    if (!(fields >> s.frame >> c1 >> s.elapsed_s >> c2 >> s.rss_mb) || c1 != ',' || c2 != ',' ||
        !std::isfinite(s.elapsed_s) || !std::isfinite(s.rss_mb))
      throw InputError(path, line_no, "expected 'frame,elapsed_s,rss_mb,fps' with numbers");
    if (!samples.empty() && s.frame <= samples.back().frame)
      throw InputError(path, line_no, "frames must increase");
    samples.push_back(s);
  }
  return samples;
}

}  // namespace cslam
