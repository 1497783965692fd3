#pragma once
// Renders a synthetic scene (SceneGeometry: textured rectangles per rigid body) as the rectified
// grey stereo pair its StereoCamera would see, with OSMesa (no display). Every surface carries
// a procedural dead-leaves texture fixed in its own coordinates (so it moves rigidly with its
// body and KLT/ORB have corners to follow at any distance), modulated by the surface's base
// colour and flat Lambert shading from one directional light fixed in the world. The pixel
// grid is exactly the camera's (fx, fy, cx, cy, width, height; right camera at +baseline along
// x), so ground-truth points project where their surfaces are drawn. Beside the pair it
// renders the id of the body seen at every left pixel, the ground truth for labelling a
// frontend's keypoints.
#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "core/rigid.h"
#include "core/stereo_camera.h"
#include "system/synthetic/scene_geometry.h"

namespace cslam {

class OptionsReader;
struct SyntheticSequence;

/// Object id of a pixel that shows no surface (sky).
constexpr uint16_t kNoObjectId = 65535;

/// How the scene is drawn.
struct SyntheticRenderOptions {
  /// One texture tile spans this many metres of a surface (each surface also scales it by a
  /// factor in [0.8, 1.25]). Outdoor scenes seen from 3–50 m: ~3 m; rooms: ~1 m. > 0.
  double texture_period_m = 3.0;
  int texture_size_px = 512;  ///< side of each texture tile, texels, power of two in [64, 2048]
  int texture_pool = 8;       ///< distinct base textures; a surface picks one, rotated and shifted
  int supersample = 1;        ///< draw k× larger per axis and box-filter down (smooth edges), 1–4
  /// Anisotropic texture filtering (when OSMesa offers it) keeps the road sharp at grazing
  /// angles, but llvmpipe's is slow (1280×720 outdoor: 4 → ~3× the time per frame), so the
  /// default is plain trilinear mip-mapping (1); in [1, 16].
  double max_anisotropy = 1;
  double ambient = 0.35;      ///< light that reaches every surface, in [0, 1]
  /// Direction towards the light in the world frame (= left camera at frame 0: x right, y
  /// down, z forward); default: from above, a little left and behind the starting camera.
  Eigen::Vector3d light_direction{-0.4, -1.0, -0.5};
  int background_grey = 200;  ///< what a pixel showing no surface gets (sky), in [0, 255]
  uint64_t texture_seed = 1;  ///< seeds the texture pool
  /// Written images only (WriteSyntheticImages): uniform integer noise in [-n, n] grey levels
  /// added to each pixel, a perturbation that measures how much a run's results move when the
  /// images change by next to nothing; 0 = none, in [0, 20].
  int grey_noise = 0;
  uint64_t grey_noise_seed = 1;  ///< seeds the grey noise (its own stream, per frame and camera)

  /// Throws ConfigError naming the field and the rule.
  void Check() const;
  void Load(OptionsReader& reader);
};

/// One rendered stereo frame.
struct RenderedStereoFrame {
  cv::Mat left, right;  ///< CV_8UC1, camera width × height
  cv::Mat object_id;    ///< CV_16UC1: object id of the surface at each left pixel centre, or
                        ///< kNoObjectId
};

/// Owns an OffscreenContext (current on the constructing thread) and the uploaded textures.
/// Not thread-safe; use it from the thread that constructed it.
class SyntheticRenderer {
 public:
  /// Throws ConfigError on bad options or a camera that cannot be rendered (non-positive size
  /// or focal length, baseline <= 0), cslam::Error when OSMesa fails.
  SyntheticRenderer(const SceneGeometry& geometry, const StereoCamera& camera,
                    const SyntheticRenderOptions& options = {});
  ~SyntheticRenderer();
  SyntheticRenderer(const SyntheticRenderer&) = delete;
  SyntheticRenderer& operator=(const SyntheticRenderer&) = delete;

  /// Renders the pair seen from `world_from_cam` (left camera) with body o posed at
  /// world_from_object[o] (one pose per body of the geometry).
  RenderedStereoFrame Render(const Pose& world_from_cam, const std::vector<Pose>& world_from_object);

  /// Renders frame `frame` of a sequence whose geometry this renderer was built with.
  RenderedStereoFrame Render(const SyntheticSequence& sequence, int frame);

  const StereoCamera& camera() const { return camera_; }

 private:
  struct Impl;
  StereoCamera camera_;
  SyntheticRenderOptions options_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cslam
