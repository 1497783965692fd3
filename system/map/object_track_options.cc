#include "system/map/object_track_options.h"

#include <cmath>

namespace cslam {

void ObjectTrackOptions::Check() const {
  CheckOption(std::isfinite(pixel_sigma) && pixel_sigma > 0, "pixel_sigma",
              "must be positive (px)", pixel_sigma);
  smoother.Check();
}

void ObjectTrackOptions::Load(OptionsReader& r) {
  r.Read("smooth", &smooth);
  r.Read("adjust", &adjust);
  r.Read("merge_co_located", &merge_co_located);
  r.Read("pixel_sigma", &pixel_sigma);
  smoother.Load(r);
}

}  // namespace cslam
