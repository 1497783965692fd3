#include "system/run/resource_chart.h"

#include <algorithm>
#include <filesystem>
#include <opencv2/core.hpp>

#include "core/errors.h"
#include "system/draw/line_chart.h"
#include "system/io/image_io.h"

namespace cslam {

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

void WriteResourceChart(const std::vector<ResourceSample>& samples, const std::string& out_dir) {
  if (samples.size() < 2) return;
  WritePng(RenderResourceChart(samples),
           (std::filesystem::path(out_dir) / "render" / "resources.png").string());
}

}  // namespace cslam
