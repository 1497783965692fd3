#pragma once
// Synthetic ground-truth stereo sequences (ClusterSLAM paper's protocol, spec §10–11): a static
// world plus rigid bodies with smooth 6-DoF trajectories, seen by a moving stereo camera.
// Landmarks are points on the bodies' surfaces; a landmark is observed when it projects into
// both images with positive disparity, its surface faces the camera and no surface blocks the
// ray to either camera. A track ends when its point is lost; when the same surface point comes
// back it gets a new landmark id (as a real frontend's tracklets would), with the same object
// label. Everything is deterministic from the seed, with one RNG stream per source (scene
// layout, trajectories, landmark sampling, pixel noise).
#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/options_reader.h"
#include "core/rigid.h"
#include "core/stereo_camera.h"
#include "core/tracklet_table.h"
#include "system/synthetic/scene_geometry.h"

namespace cslam {

/// What to generate. Presets: "indoor" (furnished room, 30 Hz, baseline 0.10 m, 2–5 moving
/// objects) and "outdoor" (street with a junction, 10 Hz, baseline 0.50 m, 5–10 moving cars).
struct SyntheticOptions {
  std::string preset = "outdoor";  ///< "indoor" or "outdoor"
  int seed = 1;                    ///< seeds every RNG stream
  int frames = 0;                  ///< number of frames, >= 2; 0 = the preset draws from its range
  int objects = -1;                ///< moving objects, >= 0; -1 = the preset draws from its range
  double noise_px = 1.5;           ///< pixel noise on uL, vL, uR: uniform half-width or sigma, px
  bool gaussian_noise = false;     ///< false: uniform in [-noise_px, noise_px]; true: N(0, noise_px²)
  double landmark_density = 1.0;   ///< multiplies the preset's surface point density, > 0
  /// Stereo baseline, m; 0 = the preset's. Only the right camera moves: the scene, the
  /// trajectories and the landmarks are those of the preset's baseline for the same seed.
  double baseline_m = 0.0;

  /// Throws ConfigError naming the field and the rule.
  void Check() const;
  /// Reads every field by its snake_case name.
  void Load(OptionsReader& reader);
};

/// A generated sequence with its ground truth. World = the left camera frame at frame 0.
struct SyntheticSequence {
  std::string name;                                  ///< e.g. "outdoor_seed1"
  StereoCamera camera;
  std::vector<double> timestamps;                    ///< seconds, per frame
  TrackletTable observations;  ///< noisy (uL, vL, uR) + pixel covariance; its num_frames() may
                               ///< be < num_frames() when the last frames see nothing
  std::vector<Pose> world_from_cam;                  ///< per frame; [0] = identity
  std::vector<std::vector<Pose>> world_from_object;  ///< [object][frame]; object 0 = static (identity)
  std::vector<int> landmark_object;                  ///< [landmark id] -> object id (0 = static)
  std::vector<Eigen::Vector3d> landmark_in_object;   ///< [landmark id] position in its object's frame, m
  SceneGeometry geometry;                            ///< [object] surfaces in the object's frame

  int num_frames() const { return static_cast<int>(world_from_cam.size()); }
  /// Objects including the static world 0.
  int num_objects() const { return static_cast<int>(world_from_object.size()); }
  /// The landmark's ground-truth position in the world frame at `frame`.
  Eigen::Vector3d LandmarkInWorld(int landmark, int frame) const {
    return world_from_object[landmark_object[landmark]][frame] * landmark_in_object[landmark];
  }
  /// Length of the camera's path, metres.
  double CameraTravel() const;
};

/// Generates the sequence described by `options` (checked first; throws ConfigError).
SyntheticSequence GenerateSynthetic(const SyntheticOptions& options);

}  // namespace cslam
