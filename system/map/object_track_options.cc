#include "system/map/object_track_options.h"

#include <cmath>

namespace cslam {

void ObjectTrackOptions::Check() const {
  CheckOption(std::isfinite(pixel_sigma) && pixel_sigma > 0, "pixel_sigma",
              "must be positive (px)", pixel_sigma);
  CheckOption(std::isfinite(join_max_gap_s) && join_max_gap_s >= 0, "join_max_gap_s",
              "must be >= 0 (seconds; 0: off)", join_max_gap_s);
  CheckOption(std::isfinite(join_max_acceleration_mps2) && join_max_acceleration_mps2 >= 0,
              "join_max_acceleration_mps2", "must be >= 0 (m/s²)", join_max_acceleration_mps2);
  smoother.Check();
}

void ObjectTrackOptions::Load(OptionsReader& r) {
  r.Read("smooth", &smooth);
  r.Read("adjust", &adjust);
  r.Read("merge_co_located", &merge_co_located);
  r.Read("join_max_gap_s", &join_max_gap_s);
  r.Read("join_max_acceleration_mps2", &join_max_acceleration_mps2);
  r.Read("pixel_sigma", &pixel_sigma);
  smoother.Load(r);
}

}  // namespace cslam
