#pragma once
// The online system's map: one camera pose per frame, cluster ids that stay stable across
// sliding windows, landmark positions in their cluster's frame and every cluster's trajectory
// (clusterslam_spec.md §7). Each backend window is estimated in its own frame (world = the
// camera at the window's first frame) with cluster frames of its own; Integrate() associates
// its clusters with the map's by shared landmarks, aligns the frames and stitches the
// trajectories. Frames: map world = the camera frame at the first integrated frame.
// Not thread-safe: the backend thread owns it and publishes copies.
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "backend/motion_estimation.h"
#include "core/options_reader.h"
#include "core/rigid.h"
#include "system/map/object_observations.h"
#include "system/map/object_track_options.h"
#include "system/map/reappearance.h"

namespace cslam {

/// Options of the cross-window association and stitching.
struct MapStateOptions {
  /// A window cluster continues a map cluster when |shared landmarks| / |window cluster's
  /// landmarks| reaches this ratio (spec §7: 70 %).
  double association_overlap = 0.7;
  /// Shared landmarks needed to align a window's cluster frame to the map's by Umeyama;
  /// fewer falls back to a shared frame of the trajectories.
  int min_shared_for_alignment = 4;
  /// Below association_overlap, a window cluster still continues a map cluster when the map
  /// cluster holds at least this fraction of the window cluster's landmarks the map already
  /// knows (new landmarks say nothing either way: outdoors they are a third of a window) and
  /// either test below passes. The static world (0) is a candidate of the motion test only.
  double known_overlap = 0.5;
  /// Containment test: the window cluster holds at least this fraction of the map cluster's
  /// landmarks that the window labelled (the object's part still in view), and at least
  /// min_shared_for_alignment of them. 1 disables it.
  double containment_overlap = 0.7;
  /// Motion test: the two trajectories agree (motion_tolerance, motion_min_frames).
  bool motion_association = true;
  /// Shared frames needed before two trajectories are compared at all.
  int motion_min_frames = 5;
  /// Two trajectories describe one rigid body when, with the best constant body-frame offset,
  /// they place the body's points within this RMS distance over the shared frames, relative
  /// to the points' mean distance from the camera (stereo depth noise grows with range).
  double motion_tolerance = 0.01;
  /// After each window, merge map clusters whose trajectories agree over at least
  /// motion_min_frames shared frames (the younger id goes, its landmarks join the older one),
  /// and fold clusters that hold still into the static world (id 0).
  bool merge_agreeing_clusters = true;
  /// ... and merge two moving clusters that occupy one place: over at least motion_min_frames
  /// shared frames, the median distance between their centroids is at most this many times
  /// the smaller one's RMS radius (system/map/co_location.h). Rigid bodies cannot overlap, so
  /// these are pieces of one body, rigid or not (a cyclist's legs and frame). 0 = off.
  double co_location_ratio = 1.0;
  /// Shared frames the place test needs (≥ 1). Fewer than motion_min_frames: a body whose
  /// tracks all turn over hands it from one window cluster to the next within a few frames,
  /// too few to compare motions, while one shared frame already shows where both pieces lie.
  int co_location_min_frames = 2;
  /// Merging compares a younger cluster's last this many frames of trajectory only, so an
  /// object tracked for minutes costs each window what a new one does. Long enough that a car
  /// waiting at a light is not folded into the static world. 0 = its whole trajectory.
  int merge_horizon_frames = 300;
  /// ... and fits each pair's motions on at most this many of their shared frames, evenly
  /// spread (a backend window's length): the comparison then costs the same for an object
  /// tracked for minutes as for a young one. 0 = every shared frame.
  int merge_max_frames = 30;
  /// How an associated window cluster's frame is aligned to the map cluster's: true, by the
  /// best constant offset between the two trajectories over their shared frames (when they
  /// share motion_min_frames), so the stitched trajectory continues the map's without a jump;
  /// false, by Umeyama on the shared landmarks' positions, whose depth noise at 30 m made the
  /// trajectory jump by up to a metre at window boundaries.
  bool stitch_by_motion = true;
  /// A window cluster that continues no map cluster starts a new one only with at least this
  /// many landmarks; smaller ones leave their landmarks as the map had them (spec §7: dropped
  /// by history). 1 creates every cluster.
  int min_new_cluster_landmarks = 1;
  /// Camera poses of known frames the window re-estimates [ours, measured]: k ≥ 1 chains the
  /// window to the map at its frame k − 1 and replaces every later frame's pose with the
  /// window's, so a frame ends with the estimate of the window where k − 1 older frames and up
  /// to window − k newer ones constrain it (a fixed-lag smoother). 0 keeps each frame's first
  /// estimate (it was among the window's newest, least constrained frames), which gave a worse
  /// online camera on KITTI raw 0005 (docs/experiments/2026-12-01-real-drive-accuracy.md).
  int refine_camera_from = 1;
  /// A moving cluster is reported as an object (objects/, renders, metrics) only with at least
  /// this many landmarks and poses at this many frames; the landmarks of smaller or shorter
  /// ones are outliers (cluster -1): a few points or a few frames say too little about a body.
  int report_min_landmarks = 5;
  int report_min_frames = 10;
  /// ... and only when at least this many backend windows found it, or every window that
  /// covered its frames when fewer did. The windows overlap by all but window_every frames,
  /// so a body in view is found again and again; a cluster that one window found and the
  /// next ones, seeing the same tracks, did not is that window's coincidence. A batch run's
  /// one whole-sequence solve covers everything once.
  int report_min_windows = 2;
  /// A landmark no window has labelled for this many frames is retired: it keeps its cluster
  /// and position for the outputs, but association, merging and stitching no longer look at
  /// it, so their cost does not grow with the run's length. A moving cluster whose landmarks
  /// are all retired is final. 0 = never.
  int retire_after_frames = 60;
  /// A moving cluster that starts after another ended, at most this long after, continues it
  /// when it lies where the old body, carried on at constant velocity, could have got to
  /// (system/map/reappearance.h): an object back from behind an occluder keeps its id.
  /// 0 = off: the bound below is a road vehicle's, and bodies that move slowly side by side
  /// (generated indoor seed 1: two boxes 2.8 m apart, 1.4 s gap) fit inside it; the KITTI
  /// configs turn it on.
  double reappearance_max_gap_s = 0;
  /// ... with at most this acceleration over the gap (m/s²; 3: a road vehicle's, braking or
  /// speeding up hard in town).
  double reappearance_max_acceleration_mps2 = 3.0;
  /// A moving cluster's landmarks keep their cluster when a window labels them static
  /// while it finds none of that cluster's landmarks moving (it lost the body).
  bool keep_lost_members = true;
  /// The reported objects' body frames and smoothed tracks at the end of the run
  /// (system/map/object_tracks.h; YAML section `map.track`).
  ObjectTrackOptions track;
  /// Two moving clusters whose landmarks lie more than this far apart are not merged (the
  /// backend's backend.assignment.split_gap_m, which the pipeline copies here; not a setting).
  double split_gap_m = 0;
  /// Time between frames; the pipeline sets it from the input's timestamps (not a setting).
  double frame_period_s = 0.1;
  void Check() const;
  void Load(OptionsReader& r);
};

/// What one Integrate() call did, for the log.
struct WindowIntegration {
  FrameRange range;
  int anchor_frame = -1;     ///< map frame the window was chained to (-1: first window or gap)
  bool gap = false;          ///< the window shares no frame with the map: chained at the last pose
  int associated = 0;        ///< window clusters that continued a map cluster
  int created = 0;           ///< window clusters that started a new map cluster
  int by_containment = 0;    ///< of `associated`, those by the containment test
  int by_motion = 0;         ///< window clusters continued by the motion test (incl. to static)
  int dropped = 0;           ///< small unassociated window clusters that created nothing
  std::vector<std::pair<int, int>> merged;  ///< (surviving map id, merged younger id); 0 = static
  std::vector<std::pair<int, int>> cluster_map;  ///< (window label, map id)
};

/// One cluster's trajectory in the map.
struct MapCluster {
  int id = -1;
  std::map<int, Pose> world_from_cluster;  ///< frame → pose, ascending frames
  int num_landmarks = 0;                   ///< landmarks currently assigned to it
  /// One window cluster's estimate of the pose at a frame, in this cluster's frame; `source`
  /// numbers the window clusters integrated into the map, so two frames of one source come
  /// from one bundle adjustment.
  struct WindowPose {
    int source = -1;
    Pose world_from_cluster = Pose::Identity();
  };
  /// Every window's estimate of its pose at each frame (the trajectory holds the first): the
  /// later windows see a frame with more context on both sides, and within one window the
  /// motion between frames is consistent even where the orientation is not; the end-of-run
  /// track fuses them (system/map/object_tracks.h).
  std::map<int, std::vector<WindowPose>> window_poses;
  /// Backend windows that found it: window clusters integrated into it, its merged clusters'
  /// included.
  int windows = 0;
};

/// Map state of the online system; see the file comment.
class MapState {
 public:
  explicit MapState(MapStateOptions options = {});

  /// Folds a window's estimate into the map. `ids` (may be null): the window's landmarks are
  /// numbered 0..m−1 and ids[l] (ascending) is landmark l's id in the map, as
  /// TrackletTable::CompactSlice numbers them, so a window costs what it holds however many
  /// landmarks the run has made; null: the window is indexed by map id.
  WindowIntegration Integrate(const MotionEstimate& window, const std::vector<int>* ids = nullptr);

  /// Frames 0..num_frames()-1; frames never covered by a window have no pose.
  int num_frames() const { return static_cast<int>(world_from_cam_.size()); }
  const std::vector<std::optional<Pose>>& world_from_cam() const { return world_from_cam_; }
  /// Moving clusters by id (static 0 is not listed).
  const std::map<int, MapCluster>& clusters() const { return clusters_; }
  /// Cluster of a landmark (-1 unknown, or an outlier: see ReleaseCluster).
  int ClusterOf(int landmark) const;
  /// Position of a landmark in its cluster's frame (world frame for static ones and outliers).
  std::optional<Eigen::Vector3d> PositionInCluster(int landmark) const;
  /// World position of a landmark at `frame` (for moving clusters, the cluster's pose then;
  /// nullopt when the cluster has no pose at that frame).
  std::optional<Eigen::Vector3d> WorldPosition(int landmark, int frame) const;
  /// Landmarks known to the map, live and retired.
  int num_landmarks() const { return static_cast<int>(landmarks_.size() + retired_.size()); }
  /// Landmarks a window labelled within the last retire_after_frames frames.
  int num_live_landmarks() const { return static_cast<int>(landmarks_.size()); }
  /// Moving clusters with at least one live landmark.
  int NumLiveClusters() const;
  /// Landmark ids known to the map, ascending.
  std::vector<int> Landmarks() const;
  /// Takes moving cluster `id` out of the map: its landmarks become outliers (cluster -1),
  /// kept at their world positions at the cluster's last pose.
  void ReleaseCluster(int id);
  /// Removes moving cluster `id`'s pose at `frame` (system/map/supported_poses.h).
  void ErasePose(int id, int frame);
  /// Re-expresses moving cluster `id` in another frame fixed to it: `cluster_from_body` maps
  /// the new frame into the old one; its poses and landmark positions change, the world
  /// positions they give do not.
  void ReframeCluster(int id, const Pose& cluster_from_body);
  /// Replaces moving cluster `id`'s trajectory (system/map/object_tracks.h).
  void SetTrajectory(int id, std::map<int, Pose> world_from_cluster);
  /// Moves a moving landmark within its cluster's frame (the end-of-run object adjustment).
  void SetPositionInCluster(int landmark, const Eigen::Vector3d& p_in_cluster);
  /// Keeps the window's keypoints of the landmarks now in moving clusters (call after
  /// Integrate with the same window; `ids` as there), for the end-of-run object tracks.
  void KeepObjectObservations(const TrackletTable& window_table, const std::vector<int>* ids) {
    object_observations_.Keep(window_table, ids, *this);
  }
  const ObjectObservations& object_observations() const { return object_observations_; }
  /// Merges moving clusters as their trajectories now stand, live and retired landmarks alike,
  /// oldest first: over fewer shared frames than motion_min_frames, those that occupy one place
  /// (co_location_ratio, co_location_min_frames: a hand-over from one cluster to the next); over
  /// more, those that move as one rigid body (motion_tolerance) and are not split_gap_m apart
  /// (a far car's pieces). Returns the (surviving, merged) pairs. For the end of a run: the
  /// windows judged both tests on their own poses, far noisier than the object tracks'
  /// (system/map/object_tracks.h). With `position_sigma_m` (a cluster's track's typical 1-σ
  /// position error, m; 0 when unknown), pairs over more frames that occupy one place also
  /// merge when their motions differ by no more than their tracks' own errors explain (χ²₃
  /// 95 % on the RMS misplacement of the points): a relative tolerance asks 0.4 m of two
  /// tracks 40 m away whose places are each only known to 0.4 m.
  std::vector<std::pair<int, int>> MergeCoLocatedClusters(
      const std::function<double(int)>& position_sigma_m = {});
  /// Merges each moving cluster that starts after another ended, within gate.max_gap_s, into
  /// it when it lies where that body could have got to (system/map/reappearance.h) and no
  /// other body could have; returns the (surviving, merged) pairs. For the end of a run, on the
  /// object tracks' poses: a window's piece of a far car that the next windows found as a new
  /// cluster a few frames later.
  std::vector<std::pair<int, int>> MergeReappearedClusters(const ReappearanceGate& gate);
  /// Integrated windows whose frames overlap [first, last].
  int WindowsCovering(int first, int last) const;
  /// Frames where consecutive windows did not overlap (the trajectory was chained blindly).
  const std::vector<int>& gaps() const { return gaps_; }

 private:
  struct LandmarkState {
    int cluster = -1;
    Eigen::Vector3d p_in_cluster = Eigen::Vector3d::Zero();
    int last_frame = -1;  ///< last frame of the last window that labelled it
  };
  struct Candidate;
  struct Association;
  const LandmarkState* Find(int landmark) const;
  /// Integrate's phases (map_state.cc).
  Pose ChainCamera(const MotionEstimate& window, WindowIntegration* info);
  std::vector<Candidate> AssociationCandidates(const MotionEstimate& window,
                                               const std::map<int, std::vector<int>>& members) const;
  void AssociateByContainment(const std::vector<Candidate>& candidates, Association* a) const;
  void AssociateByMotion(const MotionEstimate& window, const std::map<int, std::vector<int>>& members,
                         const std::vector<Candidate>& candidates, const Pose& map_from_window,
                         Association* a, WindowIntegration* info);
  std::optional<Pose> AlignToMapCluster(const MotionEstimate& window, int map_id,
                                        const std::vector<int>& ids, const ClusterMotion& motion,
                                        const Pose& map_from_window);
  void IntegrateCluster(const MotionEstimate& window, int label, const std::vector<int>& ids,
                        const ClusterMotion& motion, const Association& a,
                        const Pose& map_from_window, WindowIntegration* info);
  /// Moves the landmarks last labelled before `frame` from landmarks_ to retired_.
  void RetireBefore(int frame);
  void SetCameraPose(int frame, const Pose& world_from_cam);
  void Assign(int landmark, int cluster, const Eigen::Vector3d& p_in_cluster);
  /// Landmarks of every cluster (moving and static), in their cluster's frame.
  std::map<int, std::vector<int>> MembersByCluster() const;
  /// Merges map clusters whose motions agree or that occupy one place
  /// (merge_agreeing_clusters, co_location_ratio), recording them in `info`.
  void MergeAgreeingClusters(WindowIntegration* info);
  /// The landmarks' positions in their cluster's frame.
  std::vector<Eigen::Vector3d> PointsOf(const std::vector<int>& ids) const;
  /// Every moving cluster's landmarks in its frame, live and retired, by cluster.
  std::map<int, std::vector<Eigen::Vector3d>> MovingClusterPoints() const;
  /// Whether `b`, carried into a's frame by a_from_b, lies more than split_gap_m from every
  /// point of `a` (false when the split is off).
  bool ApartByGap(const std::vector<Eigen::Vector3d>& a, const Pose& a_from_b,
                  const std::vector<Eigen::Vector3d>& b) const;
  /// Whether the two clusters' points occupied the same space (system/map/co_location.h).
  bool CoLocated(const MapCluster& older, const std::vector<int>& older_ids,
                 const MapCluster& younger, const std::vector<Eigen::Vector3d>& younger_points) const;
  /// Moves every landmark of `younger` into `older` (older_from_younger maps the frames) and
  /// extends the older trajectory with the younger's poses at frames it lacks.
  void MergeInto(int older, int younger, const Pose& older_from_younger);

  MapStateOptions options_;
  std::vector<std::optional<Pose>> world_from_cam_;
  std::unordered_map<int, LandmarkState> landmarks_;  ///< live
  /// Retired landmarks by id: they only accumulate, so a vector indexed by id holds them in
  /// a few dozen bytes each, and retiring one costs a write, not a node in a growing table.
  class RetiredStates {
   public:
    LandmarkState* Find(int id) {
      return id >= 0 && id < static_cast<int>(present_.size()) && present_[id] ? &states_[id] : nullptr;
    }
    const LandmarkState* Find(int id) const { return const_cast<RetiredStates*>(this)->Find(id); }
    void Put(int id, const LandmarkState& state);
    void Erase(int id);
    size_t size() const { return count_; }
    template <typename F>
    void ForEach(F&& f) const {
      for (size_t id = 0; id < present_.size(); ++id)
        if (present_[id]) f(static_cast<int>(id), states_[id]);
    }

   private:
    std::vector<LandmarkState> states_;
    std::vector<char> present_;
    size_t count_ = 0;
  };
  RetiredStates retired_;
  std::unordered_map<int, std::vector<int>> retired_by_cluster_;  ///< moving clusters only
  int window_last_frame_ = -1;  ///< of the window being integrated
  int next_window_source_ = 0;  ///< MapCluster::WindowPose::source of the next window cluster
  const std::vector<int>* window_ids_ = nullptr;  ///< its compact numbering, while integrated
  /// A landmark's position in its window cluster, by map id.
  const Eigen::Vector3d& WindowPoint(const MotionEstimate& window, int landmark) const;
  std::map<int, MapCluster> clusters_;
  std::vector<int> gaps_;
  std::vector<int> window_begins_, window_ends_;  ///< of every integrated window, each sorted
  int next_cluster_id_ = 1;
  ObjectObservations object_observations_;
};

}  // namespace cslam
