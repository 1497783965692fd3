#include <opencv2/core/utility.hpp>
#include <cstdio>
#include <map>
#include <ctime>
#include "frontend/image_patch.h"
#include "core/timer.h"
#include "core/tracklet_table.h"
#include "frontend/stereo_frontend.h"
#include "frontend/klt_tracker.h"
#include "frontend/stereo_matcher.h"
#include "frontend/grid_detector.h"
#include "tests/frontend/kitti_drive_0005.h"
using namespace cslam;
int main(int argc, char** argv) {
  cv::setNumThreads(1);
  auto cam = testing::Drive0005Camera();
  if (!getenv("RUNONLY")) {
  auto p0 = testing::LoadDrive0005Pair(0);
  GridDetector det{GridDetectorOptions{}};
  auto kps = det.Detect(p0.left, {});
  std::vector<cv::Point2f> pts; for (auto& k : kps) pts.push_back(k.pt);
  StereoMatcherOptions so;
  if (getenv("HAM")) so.max_hamming = atoi(getenv("HAM"));
  if (getenv("AMB")) so.max_ambiguity = atof(getenv("AMB"));
  if (getenv("RAD")) so.refine_radius_px = atoi(getenv("RAD"));
  if (getenv("NCC")) so.min_ncc = atof(getenv("NCC"));
  if (getenv("ROW")) so.max_row_error_px = atof(getenv("ROW"));
  StereoMatcher m{so};
  for (int rep = 0; rep < 3; ++rep) {
  Timer t;
  double t1 = t.ElapsedMs(); t.Reset();
  auto ms = m.Match(p0.left, p0.right, pts);
  double t2 = t.ElapsedMs();
  std::map<int,int> reasons; for (auto& r : ms) reasons[(int)r.status]++;
  printf("detected %zu; set right %.1f ms match %.1f ms; stereo reasons:", kps.size(), t1, t2); for (auto [k,v] : reasons) printf(" %d:%d", k, v); printf("\n");
  }
  {
    auto ms = m.Match(p0.left, p0.right, pts);
    std::vector<int> hh; for (auto& r : ms) if (r.ok()) hh.push_back(r.hamming); std::sort(hh.begin(), hh.end());
    if (!hh.empty()) printf("hamming of ok: p50 %d p90 %d p99 %d\n", hh[hh.size()/2], hh[hh.size()*9/10], hh[hh.size()*99/100]);
    int shown = 0; int agree = 0, tot = 0, hi = 0;
    for (size_t i = 0; i < pts.size(); ++i) {
      ImagePatch t; if (!SamplePatch(p0.left, pts[i].x, pts[i].y, 11, &t)) continue;
      double best = -2; int bd = -1;
      for (int d = 0; d <= 160; ++d) { ImagePatch r; if (!SamplePatch(p0.right, pts[i].x - d, pts[i].y, 11, &r)) break; double c = Ncc(t, r); if (c > best) { best = c; bd = d; } }
      ++tot; if (best > 0.8) ++hi;
      if (ms[i].ok() && std::abs(pts[i].x - ms[i].u_right - bd) <= 1) ++agree;
      if (shown < 15 && !ms[i].ok()) { ++shown; printf("pt %.0f,%.0f status %d ham %d ncc %.2f | brute d %d ncc %.2f\n", pts[i].x, pts[i].y, (int)ms[i].status, ms[i].hamming, ms[i].ncc, bd, best); }
    }
    printf("brute: %d/%d have best ncc>0.8; matcher ok & agrees with brute: %d\n", hi, tot, agree);
  }
  auto cpu_ms = [] { timespec ts; clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts); return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6; };
  {
    double c0 = cpu_ms();
    for (int rep = 0; rep < 5; ++rep) m.Match(p0.left, p0.right, pts);
    printf("stereo CPU %.2f ms per call (%zu pts)\n", (cpu_ms() - c0) / 5, pts.size());
    auto p1b = testing::LoadDrive0005Pair(1);
    for (int win : {21, 15, 11}) for (int it : {20, 10}) {
      KltTrackerOptions ko; ko.window_px = win; ko.max_iterations = it;
      KltTracker trk{ko};
      double a0 = cpu_ms();
      auto A = trk.BuildPyramid(p0.left); auto B = trk.BuildPyramid(p1b.left);
      double a1 = cpu_ms();
      auto rr = trk.Track(A, B, std::span<const cv::Point2f>(pts.data(), 900));
      double a2 = cpu_ms();
      std::map<int,int> tre; for (auto& r : rr) tre[(int)r.status]++;
      printf("klt win %d it %d: 2 pyramids %.2f ms, track 900 pts %.2f ms; reasons", win, it, a1 - a0, a2 - a1); for (auto [k,v] : tre) printf(" %d:%d", k, v); printf("\n");
    }
    double d0 = cpu_ms(); for (int rep = 0; rep < 5; ++rep) det.Detect(p0.left, {}); printf("detect CPU %.2f ms\n", (cpu_ms() - d0) / 5);
  }
  // tracking reasons frame 0->1
  auto p1 = testing::LoadDrive0005Pair(1);
  KltTracker tr{KltTrackerOptions{}};
  auto a = tr.BuildPyramid(p0.left), b = tr.BuildPyramid(p1.left);
  auto res = tr.Track(a, b, pts);
  std::map<int,int> tre; for (auto& r : res) tre[(int)r.status]++;
  printf("track reasons:"); for (auto [k,v] : tre) printf(" %d:%d", k, v); printf("\n");
  std::vector<cv::Point2f> tp; for (auto& r: res) if (r.ok()) tp.push_back(r.pt);
  auto ms2 = m.Match(p1.left, p1.right, tp);
  std::map<int,int> r2; for (auto& r : ms2) r2[(int)r.status]++;
  printf("tracked-point stereo reasons:"); for (auto [k,v] : r2) printf(" %d:%d", k, v); printf("\n");

  }
  TrackletTable table;
  FrontendOptions fo;
  if (getenv("FB")) fo.tracker.max_fb_error_px = atof(getenv("FB"));
  if (getenv("WIN")) fo.tracker.window_px = atoi(getenv("WIN"));
  if (getenv("TNCC")) fo.tracker.min_ncc = atof(getenv("TNCC"));
  StereoFrontend fe(cam, fo);
  int n = argc > 1 ? atoi(argv[1]) : 20;
  for (int i = 0; i < n; ++i) {
    auto p = testing::LoadDrive0005Pair(i);
    auto s = fe.Process(i, p.left, p.right, &table);
    printf("f%2d tracked %4d created %4d lost %4d srej %4d det %4d newlm %4d obs %4d live %4d | trk %.1f det %.1f st %.1f cov %.1f tot %.1f\n",
      i, s.tracked, s.created, s.lost, s.stereo_rejected, s.detected, s.new_landmarks, s.observations, fe.num_live_tracks(), s.track_ms, s.detect_ms, s.stereo_ms, s.covariance_ms, s.total_ms);
  }
  printf("landmarks %d obs %zu\n", table.num_landmarks(), table.num_observations());
  std::vector<int> len; for (int l = 0; l < table.num_landmarks(); ++l) len.push_back(table.ObservationsOf(l).size());
  {
    std::vector<double> su, sv, sd, cuv;
    for (int l = 0; l < table.num_landmarks(); ++l) for (auto& o : table.ObservationsOf(l)) {
      su.push_back(std::sqrt(o.cov(0,0))); sv.push_back(std::sqrt(o.cov(1,1)));
      sd.push_back(std::sqrt(o.cov(0,0) + o.cov(2,2) - 2 * o.cov(0,2)));
    }
    auto med = [](std::vector<double> v, double q) { std::sort(v.begin(), v.end()); return v[size_t(q * (v.size() - 1))]; };
    printf("sigma uL p10 %.3f p50 %.3f p90 %.3f | vL p50 %.3f p90 %.3f | disparity p10 %.3f p50 %.3f p90 %.3f\n", med(su,.1), med(su,.5), med(su,.9), med(sv,.5), med(sv,.9), med(sd,.1), med(sd,.5), med(sd,.9));
  }
  std::sort(len.begin(), len.end()); double mean = 0; for (int v : len) mean += v; 
  int ge10 = 0; for (int v : len) ge10 += v >= 10;
  printf("track length mean %.2f median %d p90 %d, >=10: %d\n", mean / len.size(), len[len.size()/2], len[len.size()*9/10], ge10);
}
