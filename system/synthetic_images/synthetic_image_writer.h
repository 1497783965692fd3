#pragma once
// Renders a synthetic sequence's stereo images and object ids (OSMesa) and writes them in the
// KITTI odometry layout of system/synthetic/synthetic_image_io.h.
#include <functional>
#include <string>

#include "system/synthetic/synthetic_scene.h"
#include "system/synthetic_images/synthetic_renderer.h"

namespace cslam {

/// Renders every frame of `sequence` (left, right, object ids) and writes calib.txt,
/// times.txt, poses/00.txt and the images under `dir`, each atomically; `progress(done,
/// total)` is called after each frame when set. Throws OutputError, ConfigError (bad options)
/// or cslam::Error (OSMesa).
void WriteSyntheticImages(const SyntheticSequence& sequence, const std::string& dir,
                          const SyntheticRenderOptions& options,
                          const std::function<void(int, int)>& progress = {});

}  // namespace cslam
