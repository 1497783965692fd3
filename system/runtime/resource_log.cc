#include "system/runtime/resource_log.h"

#include <sys/resource.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <iomanip>
#include <opencv2/core.hpp>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "system/io/image_io.h"
#include "system/draw/line_chart.h"

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

void WriteResourceLog(const std::vector<ResourceSample>& samples, const std::string& out_dir,
                      bool plot) {
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
  if (plot) WritePng(RenderResourceChart(samples), (out / "render" / "resources.png").string());
}

cv::Mat RenderResourceChart(const std::vector<ResourceSample>& samples) {
  CSLAM_CHECK(samples.size() >= 2, "a resource chart needs two samples");
  LineChart memory, rate;
  memory.title = "resident memory";
  memory.x_label = rate.x_label = "frame";
  memory.y_label = "RSS (MiB)";
  memory.y_min = rate.y_min = 0;
  rate.y_label = "frames/s";
  ChartSeries m{"RSS", {}, {}, SeriesColor(0)}, r{"frames/s", {}, {}, SeriesColor(1)};
  // At most ~100 points per chart, and the rate over the whole stride between them: the
  // first frames race ahead of the first backend window, which per-sample rates would show as
  // a spike that hides the rest.
  const size_t stride = std::max<size_t>(1, samples.size() / 100);
  for (size_t i = 0; i < samples.size(); i += stride) {
    m.x.push_back(samples[i].frame);
    m.y.push_back(samples[i].rss_mb);
    if (i >= stride) {
      const ResourceSample& a = samples[i - stride];
      const double dt = samples[i].elapsed_s - a.elapsed_s;
      r.x.push_back(samples[i].frame);
      r.y.push_back(dt > 0 ? (samples[i].frame - a.frame) / dt : 0.0);
    }
  }
  rate.title = "frame rate (over " + std::to_string(stride * (samples[1].frame - samples[0].frame)) +
               "-frame spans)";
  memory.series.push_back(m);
  rate.series.push_back(r);
  cv::Mat image;
  cv::vconcat(std::vector<cv::Mat>{RenderLineChart(memory, 900, 420), RenderLineChart(rate, 900, 420)},
              image);
  return image;
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
