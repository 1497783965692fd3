#pragma once
// The default pictures of a run, drawn after it from its final outputs (RunOutputs), so they
// show the result the files hold: the clustered point cloud (render/final_snapshot_NNNNNN.png)
// and the left image with its keypoints coloured by their final cluster
// (render/final_overlay_NNNNNN.png) at a few frames spread over the run. Each carries its
// frame number and a legend whose ids are those of objects/index.csv. `cslam render` draws
// them again from the same outputs and the input recorded in cslam_outputs.json.
#include <functional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/stereo_camera.h"
#include "system/datasets/stereo_source.h"
#include "system/draw/render_scene.h"
#include "system/render/snapshot_renderer.h"
#include "system/run/run_outputs.h"

namespace cslam {

/// `dir`/`stem`_NNNNNN.png: the name of frame N's picture (six digits, as every render).
std::string NumberedPngPath(const std::string& dir, const char* stem, int frame);

/// `count` frames with a camera pose spread evenly over the run (the middles of `count` equal
/// stretches); fewer when the trajectory is shorter.
std::vector<int> SpreadFrames(const std::vector<int>& frames, int count);

/// The landmarks where they are at `frame`: static ones as written, a moving cluster's only
/// when it has a pose at `frame` (carried there from where clusters.csv placed them).
std::vector<RenderPoint> PointsAtFrame(const RunOutputs& outputs, int frame);

/// The paths up to `frame`: ground truth (dashed), camera, and each object seen at `frame`
/// through its landmarks' centroid, labelled "object <id>".
std::vector<RenderTrajectory> PathsUpToFrame(const RunOutputs& outputs, int frame);

/// The overlay tracks of `frame` (RunOutputs::keypoints) coloured by each landmark's final
/// cluster (clusters.csv; a landmark not there is an outlier, -1).
std::vector<OverlayTrack> FinalOverlayTracks(const RunOutputs& outputs, int frame);

/// The snapshot of `frame` from the final outputs, with "frame N, final estimate" written on it.
/// Throws cslam::Error when offscreen rendering is unavailable.
cv::Mat DrawFinalSnapshot(const RunOutputs& outputs, int frame, const StereoCamera& camera,
                          const SnapshotOptions& options = {});

/// The overlay of `frame` on `left`, with its frame number, a legend of the clusters drawn
/// (static, outliers, each object by its id, with its keypoint count), and the labelled boxes
/// in view (KITTI), projected from their true pose through the true camera, in the colour of
/// the object matched to them (grey: none).
cv::Mat DrawFinalOverlay(const RunOutputs& outputs, int frame, const cv::Mat& left,
                         const StereoCamera& camera);

/// One picture to draw: the file it goes to and how to draw it. Jobs are independent of each
/// other (each snapshot renders in its own offscreen context, overlays load their own image),
/// so they may run side by side.
struct PictureJob {
  std::string path;
  std::function<cv::Mat()> draw;
};

/// The final snapshot of each of `snapshot_frames` (the first snapshot_frames.size() jobs) and
/// the final overlay of each frame of outputs.keypoints (`images` may be null: no overlays), to
/// go into `render_dir`. The jobs refer to their arguments, which must outlive them.
std::vector<PictureJob> FinalPictureJobs(const RunOutputs& outputs,
                                         const std::vector<int>& snapshot_frames,
                                         const StereoCamera& camera, const StereoSource* images,
                                         const std::string& render_dir);

/// Draws and writes FinalPictureJobs(...) one after another. A picture that fails does not stop
/// the others; returns one line per picture not written.
std::vector<std::string> WriteFinalPictures(const RunOutputs& outputs,
                                            const std::vector<int>& snapshot_frames,
                                            const StereoCamera& camera, const StereoSource* images,
                                            const std::string& render_dir);

}  // namespace cslam
