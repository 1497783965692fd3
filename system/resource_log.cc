#include "system/resource_log.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <opencv2/core.hpp>

#include "core/atomic_file.h"
#include "system/image_io.h"
#include "system/line_chart.h"

namespace cslam {

double ResidentMegabytes() {
  std::ifstream statm("/proc/self/statm");
  long long size_pages = 0, resident_pages = 0;
  if (!(statm >> size_pages >> resident_pages)) return 0.0;
  return static_cast<double>(resident_pages) * static_cast<double>(sysconf(_SC_PAGESIZE)) /
         (1024.0 * 1024.0);
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
  if (!plot) return;
  LineChart memory, rate;
  memory.title = "resident memory";
  memory.x_label = rate.x_label = "frame";
  memory.y_label = "RSS (MiB)";
  memory.y_min = rate.y_min = 0;
  rate.title = "frame rate between samples";
  rate.y_label = "frames/s";
  ChartSeries m{"RSS", {}, {}, SeriesColor(0)}, r{"frames/s", {}, {}, SeriesColor(1)};
  for (size_t i = 0; i < samples.size(); ++i) {
    m.x.push_back(samples[i].frame);
    m.y.push_back(samples[i].rss_mb);
    if (i > 0) {
      r.x.push_back(samples[i].frame);
      r.y.push_back(fps[i - 1]);
    }
  }
  memory.series.push_back(m);
  rate.series.push_back(r);
  cv::Mat image;
  cv::vconcat(std::vector<cv::Mat>{RenderLineChart(memory, 900, 420), RenderLineChart(rate, 900, 420)},
              image);
  WritePng(image, (out / "render" / "resources.png").string());
}

}  // namespace cslam
