#pragma once
// KITTI raw tracklet_labels.xml (formats.md, "tracklet_labels.xml").
#include <string>
#include <vector>

#include "core/rigid.h"
#include "system/datasets/stereo_source.h"

namespace cslam {

/// Reads the labelled boxes of `xml_path` and returns them per frame ([num_frames]). Box
/// poses (bottom-face centre and yaw in the velodyne frame) are mapped to the camera with
/// `cam_from_velo`; track_id is the object's index in the file. Throws InputError naming the
/// file and line on malformed XML, missing or non-numeric fields, counts that disagree with
/// the items, non-positive sizes, or poses outside [0, num_frames).
std::vector<std::vector<ObjectBox>> ReadTrackletLabels(const std::string& xml_path,
                                                       const Pose& cam_from_velo, int num_frames);

}  // namespace cslam
