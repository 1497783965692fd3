// `cslam view OUT`: writes OUT/view.html from a finished run's output files
// (system/run/view_page.h), the page `cslam run` writes at its end.
#include <cstdio>
#include <memory>
#include <string>

#include "apps/command.h"
#include "system/run/view_page.h"

namespace cslam::apps {

Command AddViewCommand(CLI::App& app) {
  auto out = std::make_shared<std::string>();
  auto options = std::make_shared<ViewPageOptions>();
  CLI::App* sub = app.add_subcommand(
      "view", "Write OUT/view.html: the run's point cloud, trajectories and objects in one "
              "self-contained page (no network)");
  sub->add_option("out", *out, "output folder of `cslam run` or `cslam demo`")->required();
  sub->add_option("--three-js", options->three_js_dir, "folder of three.min.js (libjs-three)")
      ->capture_default_str();
  sub->add_option("--max-bytes", options->max_bytes, "size limit of the page, bytes (points are thinned to stay under it)")
      ->capture_default_str();
  return {sub, [out, options] {
            std::printf("%s\n", WriteViewPage(*out, *options).c_str());
            return 0;
          }};
}

}  // namespace cslam::apps
