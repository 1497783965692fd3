#include "system/map/object_adjustment.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <ceres/sphere_manifold.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

namespace cslam {

namespace {

constexpr double kCauchyChi2 = 7.81;   // χ²₃ 95 %: the robust kernel's scale
constexpr double kChi2Median3 = 2.366;
constexpr double kInlierGate = 16.27;  // χ²₃ 99.9 %

// A keypoint against the body's pose at its frame and its landmark's place in the body.
struct Reprojection {
  Reprojection(const StereoCamera& camera, const Pose& cam_from_world, const Eigen::Vector3d& x,
               const Eigen::Matrix3d& whiten)
      : camera(camera), cam_from_world(cam_from_world), x(x), whiten(whiten) {}
  template <typename T>
  bool operator()(const T* q, const T* t, const T* p, T* residual) const {
    T pw[3];
    ceres::QuaternionRotatePoint(q, p, pw);
    Eigen::Matrix<T, 3, 1> world(pw[0] + t[0], pw[1] + t[1], pw[2] + t[2]);
    const Eigen::Matrix<T, 3, 1> in_cam =
        cam_from_world.linear().cast<T>() * world + cam_from_world.translation().cast<T>();
    Eigen::Matrix<T, 3, 1> projected;
    camera.Project(in_cam, &projected);
    Eigen::Map<Eigen::Matrix<T, 3, 1>> r(residual);
    r = whiten.cast<T>() * (x.cast<T>() - projected);
    return true;
  }
  const StereoCamera& camera;
  Pose cam_from_world;
  Eigen::Vector3d x;
  Eigen::Matrix3d whiten;
};

// Three consecutive poses: the change of velocity and of angular velocity (world) between the
// two intervals, each over the spread the motion model allows in their mean duration.
struct SmoothMotion {
  SmoothMotion(double dt1, double dt2, double acceleration, double angular_acceleration)
      : dt1(dt1), dt2(dt2) {
    const double span = std::sqrt((dt1 + dt2) / 2);
    velocity_sigma = acceleration * span;
    rate_sigma = angular_acceleration * span;
  }
  template <typename T>
  bool operator()(const T* q0, const T* t0, const T* q1, const T* t1, const T* q2, const T* t2,
                  T* residual) const {
    for (int i = 0; i < 3; ++i)
      residual[i] = ((t2[i] - t1[i]) / dt2 - (t1[i] - t0[i]) / dt1) / velocity_sigma;
    T w1[3], w2[3];
    Turn(q0, q1, w1);
    Turn(q1, q2, w2);
    for (int i = 0; i < 3; ++i) residual[3 + i] = (w2[i] / dt2 - w1[i] / dt1) / rate_sigma;
    return true;
  }
  // The rotation from a to b, left (world): b a⁻¹, as an angle-axis vector.
  template <typename T>
  static void Turn(const T* a, const T* b, T* w) {
    const T a_inv[4] = {a[0], -a[1], -a[2], -a[3]};
    T d[4];
    ceres::QuaternionProduct(b, a_inv, d);
    if (d[0] < T(0))
      for (T& v : d) v = -v;
    ceres::QuaternionToAngleAxis(d, w);
  }
  double dt1, dt2, velocity_sigma = 1, rate_sigma = 1;
};

// Two consecutive poses: the angular velocity between them against its stationary spread,
// in the body frame: `vertical` (rad/s) about its y axis, the world's vertical at the body's
// first frame, and `tilt` about its two horizontal axes. The smoother's angular velocity
// reverts to zero; without this, a body spinning at a constant rate would cost nothing, and a
// far body whose keypoints hardly fix its heading was fitted turning by 18° per frame.
struct AngularRate {
  AngularRate(double dt, double vertical, double tilt) : dt(dt), vertical(vertical), tilt(tilt) {}
  template <typename T>
  bool operator()(const T* q0, const T* q1, T* residual) const {
    T w[3], q_inv[4] = {q1[0], -q1[1], -q1[2], -q1[3]}, in_body[3];
    SmoothMotion::Turn(q0, q1, w);
    ceres::QuaternionRotatePoint(q_inv, w, in_body);
    residual[0] = in_body[0] / (dt * tilt);
    residual[1] = in_body[1] / (dt * vertical);
    residual[2] = in_body[2] / (dt * tilt);
    return true;
  }
  double dt, vertical, tilt;
};

// The windows' turn of the body between two frames (world, left) against the poses' turn.
struct WindowTurn {
  WindowTurn(const Eigen::Matrix3d& turn, const Eigen::Matrix3d& whiten)
      : inverse(Eigen::Quaterniond(turn).conjugate()), whiten(whiten) {}
  template <typename T>
  bool operator()(const T* q0, const T* q1, T* residual) const {
    const T m_inv[4] = {T(inverse.w()), T(inverse.x()), T(inverse.y()), T(inverse.z())};
    T q0_inv[4] = {q0[0], -q0[1], -q0[2], -q0[3]};
    T turn[4], error[4];
    ceres::QuaternionProduct(q1, q0_inv, turn);
    ceres::QuaternionProduct(turn, m_inv, error);
    if (error[0] < T(0))
      for (T& v : error) v = -v;
    T w[3];
    ceres::QuaternionToAngleAxis(error, w);
    Eigen::Map<Eigen::Matrix<T, 3, 1>> r(residual);
    r = whiten.cast<T>() * Eigen::Matrix<T, 3, 1>(w[0], w[1], w[2]);
    return true;
  }
  Eigen::Quaterniond inverse;
  Eigen::Matrix3d whiten;
};

// Three consecutive poses and the body's direction of travel u (unit, body frame): a vehicle
// moves along its heading, so the middle pose's velocity (world, central difference) seen in
// the body frame has no component across u, up to a slip of `sigma` (m/s). Either sign of u:
// a car may reverse.
struct AlongHeading {
  AlongHeading(double dt, double sigma) : dt(dt), sigma(sigma) {}
  template <typename T>
  bool operator()(const T* t0, const T* q1, const T* t2, const T* u, T* residual) const {
    T v[3], q_inv[4] = {q1[0], -q1[1], -q1[2], -q1[3]}, vb[3];
    for (int i = 0; i < 3; ++i) v[i] = (t2[i] - t0[i]) / T(dt);
    ceres::QuaternionRotatePoint(q_inv, v, vb);
    const T along = vb[0] * u[0] + vb[1] * u[1] + vb[2] * u[2];
    for (int i = 0; i < 3; ++i) residual[i] = (vb[i] - along * u[i]) / T(sigma);
    return true;
  }
  double dt, sigma;
};

struct FramePose {
  double q[4];
  double t[3];
};

Eigen::Matrix3d Whitening(const Eigen::Matrix3d& cov) {
  // L⁻¹ of cov = L Lᵀ: |L⁻¹ r|² is the squared Mahalanobis distance.
  const Eigen::LLT<Eigen::Matrix3d> llt(cov);
  return llt.matrixL().solve(Eigen::Matrix3d::Identity());
}


// What a solve works on: poses, places and the direction of travel.
struct FitState {
  std::map<int, FramePose> poses;
  std::vector<Eigen::Vector3d> places;
  Eigen::Vector3d heading = Eigen::Vector3d::UnitZ();  // in the body frame, either sign
};

// One stretch's fit: what FitStretch did.
struct StretchFit {
  bool ok = false;
  double keypoint_scale = 1;
};

// Fits the poses of one stretch (frames tied together by shared landmarks) and its landmarks'
// places to its keypoints under the motion model; its first pose is held. `poses` and `places`
// change only when the fit succeeds.
StretchFit FitStretch(const std::vector<const ObjectKeypoint*>& used,
                      const std::vector<ObjectTurn>& turns, std::vector<Eigen::Vector3d>& places,
                      std::map<int, FramePose>& poses,
                      const std::vector<std::optional<Pose>>& world_from_cam,
                      const StereoCamera& camera, const std::function<double(int)>& time_of,
                      const TrackSmootherOptions& motion, const TaskRunner* runner) {
  StretchFit fit;
  // The angular acceleration the smoother's mean-reverting rate allows: its driving noise.
  const double angular_acceleration =
      std::sqrt(2 * motion.angular_rate_sigma_radps * motion.angular_rate_sigma_radps /
                motion.angular_rate_time_s);
  const double heading_sigma = motion.lateral_velocity_mps;
  const double tilt = motion.tilt_rate_sigma_radps > 0 ? motion.tilt_rate_sigma_radps
                                                       : motion.angular_rate_sigma_radps;
  ceres::SphereManifold<3> sphere;
  // One solve from `state`, which it leaves at the solution; the starts below run side by side.
  const auto solve = [&](FitState& state, double keypoint_scale, bool along_heading,
                         double* final_cost) {
    std::map<int, FramePose>& poses = state.poses;
    std::vector<Eigen::Vector3d>& places = state.places;
    Eigen::Vector3d& heading = state.heading;
    ceres::Problem::Options problem_options;
    problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem problem(problem_options);
    ceres::QuaternionManifold quaternion;
    for (const ObjectKeypoint* k : used) {
      FramePose& pose = poses.at(k->frame);
      auto* cost = new ceres::AutoDiffCostFunction<Reprojection, 3, 4, 3, 3>(new Reprojection(
          camera, world_from_cam[k->frame]->inverse(), k->x, Whitening(keypoint_scale * k->cov)));
      problem.AddResidualBlock(cost, new ceres::CauchyLoss(std::sqrt(kCauchyChi2)), pose.q, pose.t,
                               places[k->landmark].data());
    }
    for (auto& [f, pose] : poses) problem.SetManifold(pose.q, &quaternion);
    problem.SetParameterBlockConstant(poses.begin()->second.q);
    problem.SetParameterBlockConstant(poses.begin()->second.t);
    for (const ObjectTurn& turn : turns) {
      const auto a = poses.find(turn.from_frame), b = poses.find(turn.to_frame);
      if (a == poses.end() || b == poses.end()) continue;
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<WindowTurn, 3, 4, 4>(
                                   new WindowTurn(turn.turn, Whitening(turn.cov))),
                               new ceres::CauchyLoss(std::sqrt(kCauchyChi2)), a->second.q, b->second.q);
    }
    for (auto it = std::next(poses.begin()); it != poses.end(); ++it) {
      const double dt = time_of(it->first) - time_of(std::prev(it)->first);
      if (!(dt > 0)) continue;
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<AngularRate, 3, 4, 4>(
                                   new AngularRate(dt, motion.angular_rate_sigma_radps, tilt)),
                               nullptr, std::prev(it)->second.q, it->second.q);
    }
    if (along_heading) {
      for (auto it = std::next(poses.begin()); std::next(it) != poses.end(); ++it) {
        const double dt = time_of(std::next(it)->first) - time_of(std::prev(it)->first);
        if (!(dt > 0)) continue;
        problem.AddResidualBlock(new ceres::AutoDiffCostFunction<AlongHeading, 3, 3, 4, 3, 3>(
                                     new AlongHeading(dt, heading_sigma)),
                                 nullptr, std::prev(it)->second.t, it->second.q,
                                 std::next(it)->second.t, heading.data());
      }
      problem.SetManifold(heading.data(), &sphere);
    }
    for (auto it = std::next(poses.begin()); std::next(it) != poses.end(); ++it) {
      auto& a = std::prev(it)->second;
      auto& b = it->second;
      auto& c = std::next(it)->second;
      const double dt1 = time_of(it->first) - time_of(std::prev(it)->first);
      const double dt2 = time_of(std::next(it)->first) - time_of(it->first);
      if (!(dt1 > 0) || !(dt2 > 0)) continue;
      auto* cost = new ceres::AutoDiffCostFunction<SmoothMotion, 6, 4, 3, 4, 3, 4, 3>(
          new SmoothMotion(dt1, dt2, motion.acceleration_mps2, angular_acceleration));
      problem.AddResidualBlock(cost, nullptr, a.q, a.t, b.q, b.t, c.q, c.t);
    }
    ceres::Solver::Options options;
    // The normal equations, not the Schur complement: the steps are the same, but Ceres 2.1's
    // Schur path with Eigen rebuilds and sorts the reduced matrix at every iteration. Eigen's sparse
    // Cholesky, not CHOLMOD: CHOLMOD runs OpenMP threads of its own, outside the system's
    // threads and its core reservation (and outside ThreadSanitizer's view).
    options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    options.sparse_linear_algebra_library_type = ceres::EIGEN_SPARSE;
    options.max_num_iterations = 50;
    // Ceres' default 1e-6 ran most fits to the iteration cap, to the same tracks that 1e-5
    // ends at far sooner.
    options.function_tolerance = 1e-5;
    options.num_threads = 1;
    options.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    *final_cost = summary.final_cost;
    return summary.IsSolutionUsable() && summary.final_cost <= summary.initial_cost;
  };

  const FitState start{poses, places};
  FitState current = start;
  double final_cost = 0;
  if (!solve(current, 1.0, false, &final_cost)) return fit;
  // The keypoints' spread about the fit says how far to trust their covariances.
  std::vector<double> squared;
  squared.reserve(used.size());
  for (const ObjectKeypoint* k : used) {
    double r[3];
    const FramePose& pose = current.poses.at(k->frame);
    Reprojection(camera, world_from_cam[k->frame]->inverse(), k->x, Whitening(k->cov))(
        pose.q, pose.t, current.places[k->landmark].data(), r);
    squared.push_back(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
  }
  std::nth_element(squared.begin(), squared.begin() + squared.size() / 2, squared.end());
  fit.keypoint_scale = std::max(1.0, squared[squared.size() / 2] / kChi2Median3);
  if (fit.keypoint_scale > 1.5) {
    current = start;
    if (!solve(current, fit.keypoint_scale, false, &final_cost)) return fit;
  }
  if (heading_sigma > 0) {
    // Several starts, the lowest cost kept, each with the dominant direction of its velocities
    // in the body frame. A far body's spin in the given track blurs its direction; the free fit
    // may have followed the windows' turns into the spin.
    const auto direction_of_travel = [](const std::map<int, FramePose>& track) {
      Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
      for (auto it = std::next(track.begin()); std::next(it) != track.end(); ++it) {
        const FramePose& a = std::prev(it)->second;
        const FramePose& b = it->second;
        const FramePose& c = std::next(it)->second;
        const Eigen::Vector3d v(c.t[0] - a.t[0], c.t[1] - a.t[1], c.t[2] - a.t[2]);
        const Eigen::Vector3d in_body =
            Eigen::Quaterniond(b.q[0], b.q[1], b.q[2], b.q[3]).normalized().conjugate() * v;
        scatter += in_body * in_body.transpose();
      }
      return Eigen::Vector3d(
          Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(2).normalized());
    };
    // Three starts: the free fit, the given track, and the given track without its turns (a
    // far car crossing the view was given, and fitted from both others, a spin of 100° over
    // 40 frames while it drove straight: its keypoints hardly fix its heading, and a spin that
    // came in slowly is a valley of its own). Each with the direction of travel it shows.
    FitState straight = start;
    const FramePose first = straight.poses.begin()->second;
    for (auto& [f, pose] : straight.poses) std::copy(std::begin(first.q), std::end(first.q), pose.q);
    std::vector<FitState> starts = {std::move(current), start, std::move(straight)};
    std::vector<double> finals(starts.size(), std::numeric_limits<double>::infinity());
    RunTasks(runner, static_cast<int>(starts.size()), [&](int i) {
      FitState& state = starts[i];
      state.heading = direction_of_travel(state.poses);
      double final = 0;
      if (solve(state, fit.keypoint_scale, true, &final)) finals[i] = final;
    });
    const size_t best = std::min_element(finals.begin(), finals.end()) - finals.begin();
    if (!std::isfinite(finals[best])) return fit;
    current = std::move(starts[best]);
  }
  poses = std::move(current.poses);
  places = std::move(current.places);
  fit.ok = true;
  return fit;
}

// The frames in stretches, cut between two consecutive frames where fewer than 3 landmarks
// were seen both before and after: fewer points do not fix a rigid body's pose, so nothing in
// the keypoints ties the poses on one side to those on the other.
std::vector<std::vector<int>> Stretches(const std::vector<const ObjectKeypoint*>& used) {
  std::map<int, std::pair<int, int>> span;  // landmark → first and last frame seen
  std::map<int, int> opened;                // frame → landmarks first seen minus last seen there
  for (const ObjectKeypoint* k : used) {
    const auto [it, fresh] = span.try_emplace(k->landmark, k->frame, k->frame);
    it->second.first = std::min(it->second.first, k->frame);
    it->second.second = std::max(it->second.second, k->frame);
    opened.try_emplace(k->frame, 0);
  }
  for (const auto& [l, s] : span) {
    ++opened[s.first];
    --opened[s.second];
  }
  std::vector<std::vector<int>> out(1);
  int spanning = 0;  // landmarks seen at or before this frame and after it
  for (const auto& [f, change] : opened) {
    out.back().push_back(f);
    spanning += change;
    if (spanning < 3) out.emplace_back();
  }
  if (out.back().empty()) out.pop_back();
  return out;
}

}  // namespace

ObjectAdjustment AdjustObject(const std::vector<ObjectKeypoint>& keypoints,
                              const std::vector<ObjectTurn>& turns,
                              std::vector<Eigen::Vector3d>* in_body,
                              std::map<int, Pose>* world_from_body,
                              const std::vector<std::optional<Pose>>& world_from_cam,
                              const StereoCamera& camera, const std::function<double(int)>& time_of,
                              const TrackSmootherOptions& motion, const TaskRunner* runner) {
  ObjectAdjustment out;
  std::map<int, int> count;
  for (const ObjectKeypoint& k : keypoints)
    if (world_from_body->count(k.frame) && k.frame < static_cast<int>(world_from_cam.size()) &&
        world_from_cam[k.frame])
      ++count[k.frame];
  std::map<int, FramePose> poses;
  for (const auto& [f, n] : count) {
    if (n < 3) continue;
    const Pose& p = world_from_body->at(f);
    const Eigen::Quaterniond q(p.linear());
    poses[f] = FramePose{{q.w(), q.x(), q.y(), q.z()}, {p.translation().x(), p.translation().y(), p.translation().z()}};
  }
  if (poses.size() < 3) return out;
  std::vector<Eigen::Vector3d> places = *in_body;
  std::vector<const ObjectKeypoint*> used;
  for (const ObjectKeypoint& k : keypoints)
    if (poses.count(k.frame) && k.landmark >= 0 && k.landmark < static_cast<int>(places.size()))
      used.push_back(&k);

  // Each stretch on its own, its first pose held where the track has it: fitted together,
  // stretches that share no landmark are tied only by the motion model, metres of slack over
  // an occlusion, and a later one slid off with its landmarks where the windows, which
  // carried the body across, had it right.
  std::map<int, Pose> adjusted;
  std::vector<int> fitting(places.size(), 0), seen(places.size(), 0);
  size_t largest = 0;
  for (const std::vector<int>& frames : Stretches(used)) {
    std::map<int, FramePose> stretch;
    for (int f : frames) stretch[f] = poses.at(f);
    std::vector<const ObjectKeypoint*> own;
    for (const ObjectKeypoint* k : used)
      if (stretch.count(k->frame)) own.push_back(k);
    // Too short to fit: its frames go with the stretches about them, like frames without
    // keypoints.
    if (stretch.size() < 3) continue;
    const std::map<int, FramePose> given_poses = stretch;
    const StretchFit fit =
        FitStretch(own, turns, places, stretch, world_from_cam, camera, time_of, motion, runner);
    // A fit that explains fewer than half of the keypoints (within the χ²₃ 99.9 % gate, at
    // their scaled covariances) started too far from the body to find it: the stretch keeps
    // its track.
    int inliers = 0;
    std::vector<std::pair<int, bool>> verdicts;
    for (const ObjectKeypoint* k : own) {
      double r[3];
      const FramePose& pose = stretch.at(k->frame);
      Reprojection(camera, world_from_cam[k->frame]->inverse(), k->x,
                   Whitening(fit.keypoint_scale * k->cov))(pose.q, pose.t, places[k->landmark].data(), r);
      const bool inlier = r[0] * r[0] + r[1] * r[1] + r[2] * r[2] < kInlierGate;
      inliers += inlier;
      verdicts.emplace_back(k->landmark, inlier);
    }
    if (!fit.ok || 2 * inliers < static_cast<int>(own.size())) {
      // Its places count as unexplained and go back to the given ones below.
      stretch = given_poses;
    } else {
      out.inliers += inliers;
      out.keypoints += static_cast<int>(own.size());
      out.frames += static_cast<int>(stretch.size());
      ++out.stretches;
      for (const auto& [l, inlier] : verdicts) {
        fitting[l] += inlier;
        ++seen[l];
      }
      if (stretch.size() > largest) {
        largest = stretch.size();
        out.keypoint_scale = fit.keypoint_scale;
      }
    }
    for (const auto& [f, pose] : stretch) {
      Pose p = Pose::Identity();
      p.linear() = Eigen::Quaterniond(pose.q[0], pose.q[1], pose.q[2], pose.q[3]).normalized().toRotationMatrix();
      p.translation() = Eigen::Vector3d(pose.t[0], pose.t[1], pose.t[2]);
      adjusted[f] = p;
    }
  }
  if (out.frames == 0) return ObjectAdjustment{};
  // Every pose: the fitted ones, and the others moved with the adjusted frames about them, so
  // that the track's own motion between them is kept.
  std::map<int, Pose> track;
  for (const auto& [f, given] : *world_from_body) {
    if (const auto a = adjusted.find(f); a != adjusted.end()) {
      track[f] = a->second;
      continue;
    }
    const auto next = adjusted.lower_bound(f);
    const auto correction = [&](std::map<int, Pose>::const_iterator a) {
      return Pose(a->second * world_from_body->at(a->first).inverse());
    };
    if (next == adjusted.end() || next == adjusted.begin()) {
      track[f] = Pose(correction(next == adjusted.end() ? std::prev(next) : next) * given);
      continue;
    }
    // Between two adjusted frames the correction goes over from one's to the other's, taken
    // in the body frame (given⁻¹ adjusted), where it is small: moved with the nearer one alone,
    // a gap's frames met in the middle with a step; blended in the world, a small turn's lever
    // arm to the world origin put one there.
    const auto before = std::prev(next);
    const double w = static_cast<double>(f - before->first) / (next->first - before->first);
    const Pose a = Pose(world_from_body->at(before->first).inverse() * before->second);
    const Pose b = Pose(world_from_body->at(next->first).inverse() * next->second);
    Pose blend = Pose::Identity();
    blend.linear() = Eigen::Quaterniond(a.linear()).slerp(w, Eigen::Quaterniond(b.linear())).toRotationMatrix();
    blend.translation() = (1 - w) * a.translation() + w * b.translation();
    track[f] = Pose(given * blend);
  }
  // What a body can do between frames, at the χ²₃ 99.9 % bound of the motion model: a fit
  // that turns a body or changes its velocity by more somewhere has followed keypoints of
  // something that is not one rigid body (a cyclist's legs) or left the body: keep the track.
  const double bound = std::sqrt(kInlierGate);
  for (auto it = std::next(track.begin()); it != track.end(); ++it) {
    const auto before = std::prev(it);
    if (it->first != before->first + 1) continue;  // a gap: the track starts again
    const double dt = time_of(it->first) - time_of(before->first);
    if (!(dt > 0)) continue;
    const double turn = RotationAngle(it->second.linear() * before->second.linear().transpose());
    const double max_turn = bound * motion.angular_rate_sigma_radps * dt;
    if (turn > max_turn) {
      out.implausible = true;
      out.implausible_frame = it->first;
      out.implausible_turn = true;
      out.implausible_value = turn;
      out.implausible_bound = max_turn;
      return out;
    }
    const auto after = std::next(it);
    if (after == track.end() || after->first != it->first + 1) continue;
    const double dt2 = time_of(after->first) - time_of(it->first);
    if (!(dt2 > 0)) continue;
    const Eigen::Vector3d dv = (after->second.translation() - it->second.translation()) / dt2 -
                               (it->second.translation() - before->second.translation()) / dt;
    const double max_change = bound * motion.acceleration_mps2 * std::sqrt((dt + dt2) / 2);
    if (dv.norm() > max_change) {
      out.implausible = true;
      out.implausible_frame = it->first;
      out.implausible_value = dv.norm();
      out.implausible_bound = max_change;
      return out;
    }
  }
  out.explained.assign(places.size(), false);
  for (size_t i = 0; i < places.size(); ++i) {
    out.explained[i] = 2 * fitting[i] > seen[i];
    if (!out.explained[i]) places[i] = (*in_body)[i];
  }
  *world_from_body = std::move(track);
  *in_body = std::move(places);
  out.adjusted = true;
  return out;
}

}  // namespace cslam
