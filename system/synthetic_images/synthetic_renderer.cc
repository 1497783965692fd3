#include "system/synthetic_images/synthetic_renderer.h"

#include <GL/gl.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <string>

#include "core/errors.h"
#include "core/options_reader.h"
#include "system/render/offscreen_context.h"
#include "system/render/render_view.h"
#include "system/synthetic_images/procedural_texture.h"
#include "system/synthetic/synthetic_scene.h"

#ifndef GL_TEXTURE_MAX_ANISOTROPY_EXT
#define GL_TEXTURE_MAX_ANISOTROPY_EXT 0x84FE
#define GL_MAX_TEXTURE_MAX_ANISOTROPY_EXT 0x84FF
#endif

namespace cslam {

void SyntheticRenderOptions::Check() const {
  CheckOption(std::isfinite(texture_period_m) && texture_period_m > 0, "texture_period_m",
              "must be > 0 m", texture_period_m);
  CheckOption(texture_size_px >= 64 && texture_size_px <= 2048 &&
                  (texture_size_px & (texture_size_px - 1)) == 0,
              "texture_size_px", "must be a power of two in [64, 2048]", texture_size_px);
  CheckOption(texture_pool >= 1 && texture_pool <= 64, "texture_pool", "must be in [1, 64]",
              texture_pool);
  CheckOption(supersample >= 1 && supersample <= 4, "supersample", "must be in [1, 4]", supersample);
  CheckOption(max_anisotropy >= 1 && max_anisotropy <= 16, "max_anisotropy", "must be in [1, 16]",
              max_anisotropy);
  CheckOption(std::isfinite(ambient) && ambient >= 0 && ambient <= 1, "ambient", "must be in [0, 1]",
              ambient);
  CheckOption(light_direction.allFinite() && light_direction.norm() > 1e-9, "light_direction",
              "must be a finite non-zero vector", light_direction.norm());
  CheckOption(background_grey >= 0 && background_grey <= 255, "background_grey",
              "must be in [0, 255]", background_grey);
  CheckOption(grey_noise >= 0 && grey_noise <= 20, "grey_noise", "must be in [0, 20] grey levels", grey_noise);
}

void SyntheticRenderOptions::Load(OptionsReader& reader) {
  reader.Read("texture_period_m", &texture_period_m);
  reader.Read("texture_size_px", &texture_size_px);
  reader.Read("texture_pool", &texture_pool);
  reader.Read("supersample", &supersample);
  reader.Read("max_anisotropy", &max_anisotropy);
  reader.Read("ambient", &ambient);
  std::vector<double> light(light_direction.data(), light_direction.data() + 3);
  reader.Read("light_direction", &light);
  if (light.size() != 3)
    throw ConfigError(reader.Where("light_direction") + ": expected 3 numbers, got " +
                      std::to_string(light.size()));
  light_direction = Eigen::Vector3d(light[0], light[1], light[2]);
  reader.Read("background_grey", &background_grey);
  reader.Read("grey_noise", &grey_noise);
  int noise_seed = static_cast<int>(grey_noise_seed);
  reader.Read("grey_noise_seed", &noise_seed);
  grey_noise_seed = static_cast<uint64_t>(noise_seed);
  int seed = static_cast<int>(texture_seed);
  reader.Read("texture_seed", &seed);
  texture_seed = static_cast<uint64_t>(seed);
}

namespace {

uint64_t SplitMix(uint64_t z) {
  z += 0x9E3779B97F4A7C15ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

double Unit(uint64_t bits) { return static_cast<double>(bits >> 11) * 0x1.0p-53; }

/// How one surface wears its texture: which pool entry, and the map from the rectangle's
/// metric coordinates (metres along edge_u, edge_v) to texture coordinates.
struct SurfaceTexture {
  int pool_index = 0;
  Eigen::Matrix2d st_from_metres = Eigen::Matrix2d::Identity();
  Eigen::Vector2d offset = Eigen::Vector2d::Zero();
};

/// Fixed by the quad's texture seed alone: surfaces that share a seed (the faces of one box)
/// look alike, and the pattern never depends on the order of drawing.
SurfaceTexture TextureOf(int texture, const SyntheticRenderOptions& o) {
  uint64_t h = SplitMix(static_cast<uint64_t>(static_cast<uint32_t>(texture)) ^ (o.texture_seed << 32));
  SurfaceTexture t;
  t.pool_index = static_cast<int>(h % static_cast<uint64_t>(o.texture_pool));
  h = SplitMix(h);
  const double angle = 2.0 * std::numbers::pi * Unit(h);
  h = SplitMix(h);
  const double scale = 0.8 * std::pow(1.25 / 0.8, Unit(h));  // log-uniform in [0.8, 1.25]
  h = SplitMix(h);
  t.offset.x() = Unit(h);
  h = SplitMix(h);
  t.offset.y() = Unit(h);
  const double k = 1.0 / (o.texture_period_m * scale);
  t.st_from_metres << k * std::cos(angle), -k * std::sin(angle), k * std::sin(angle), k * std::cos(angle);
  return t;
}

/// Perceived grey of a linear RGB base colour, lifted so that dark paints (tyres, glass) keep
/// some texture contrast.
double Albedo(const Eigen::Vector3f& rgb) {
  const double luma = 0.2126 * rgb.x() + 0.7152 * rgb.y() + 0.0722 * rgb.z();
  return 0.35 + 0.65 * std::clamp(luma, 0.0, 1.0);
}

void LoadMatrix(GLenum mode, const Eigen::Matrix4d& m) {
  glMatrixMode(mode);
  glLoadMatrixd(m.data());  // Eigen is column-major, as GL expects
}

}  // namespace

struct SyntheticRenderer::Impl {
  /// A quad ready to draw: its corners in its body's frame with texture coordinates.
  struct DrawQuad {
    Eigen::Vector3d corner[4];
    Eigen::Vector2d st[4];
    Eigen::Vector3d normal;  ///< body frame
    double albedo = 0.5;
    int pool_index = 0;
  };

  Impl(int w, int h) : context(w, h) {}

  OffscreenContext context;
  std::vector<GLuint> textures;
  std::vector<std::vector<DrawQuad>> bodies;  // [object]
  float max_anisotropy = 1.0f;
};

SyntheticRenderer::SyntheticRenderer(const SceneGeometry& geometry, const StereoCamera& camera,
                                     const SyntheticRenderOptions& options)
    : camera_(camera), options_(options) {
  options_.Check();
  camera_.Check();
  CheckOption(camera_.width > 0 && camera_.height > 0, "camera.width", "must be > 0 (image size)",
              camera_.width);
  if (geometry.bodies.size() >= kNoObjectId)
    throw ConfigError("synthetic renderer: at most " + std::to_string(kNoObjectId - 1) +
                      " bodies fit the 16-bit object ids, got " + std::to_string(geometry.bodies.size()));
  impl_ = std::make_unique<Impl>(camera_.width * options_.supersample,
                                 camera_.height * options_.supersample);

  const char* ext = reinterpret_cast<const char*>(glGetString(GL_EXTENSIONS));
  if (ext != nullptr && std::strstr(ext, "GL_EXT_texture_filter_anisotropic") != nullptr) {
    // Ground seen at grazing angles would blur to grey under isotropic mip-mapping.
    glGetFloatv(GL_MAX_TEXTURE_MAX_ANISOTROPY_EXT, &impl_->max_anisotropy);
    impl_->max_anisotropy = std::min(impl_->max_anisotropy, static_cast<float>(options_.max_anisotropy));
  }

  // The texture pool, with mip levels made here (box filter) so they are the same everywhere.
  ProceduralTextureOptions tex;
  tex.size_px = options_.texture_size_px;
  tex.max_radius_px = std::min(60.0 * options_.texture_size_px / 512.0, options_.texture_size_px / 2.0);
  impl_->textures.resize(options_.texture_pool);
  glGenTextures(options_.texture_pool, impl_->textures.data());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  for (int i = 0; i < options_.texture_pool; ++i) {
    glBindTexture(GL_TEXTURE_2D, impl_->textures[i]);
    cv::Mat level = MakeDeadLeavesTexture(SplitMix(options_.texture_seed * 1000003ULL + i), tex);
    for (int l = 0;; ++l) {
      glTexImage2D(GL_TEXTURE_2D, l, GL_LUMINANCE8, level.cols, level.rows, 0, GL_LUMINANCE,
                   GL_UNSIGNED_BYTE, level.data);
      if (level.cols == 1) break;
      cv::Mat half;
      cv::resize(level, half, cv::Size(level.cols / 2, level.rows / 2), 0, 0, cv::INTER_AREA);
      level = half;
    }
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    if (impl_->max_anisotropy > 1.0f)
      glTexParameterf(GL_TEXTURE_2D, GL_TEXTURE_MAX_ANISOTROPY_EXT, impl_->max_anisotropy);
  }

  for (const SceneBody& body : geometry.bodies) {
    std::vector<Impl::DrawQuad> quads;
    for (const SceneQuad& q : body.quads) {
      const SurfaceTexture t = TextureOf(q.texture, options_);
      Impl::DrawQuad d;
      const double lu = q.edge_u.norm(), lv = q.edge_v.norm();
      const double ab[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
      for (int k = 0; k < 4; ++k) {
        d.corner[k] = q.At(ab[k][0], ab[k][1]);
        d.st[k] = t.offset + t.st_from_metres * Eigen::Vector2d(ab[k][0] * lu, ab[k][1] * lv);
      }
      d.normal = q.Normal();
      d.albedo = Albedo(q.color);
      d.pool_index = t.pool_index;
      quads.push_back(d);
    }
    impl_->bodies.push_back(std::move(quads));
  }
}

SyntheticRenderer::~SyntheticRenderer() {
  if (impl_ && !impl_->textures.empty()) {
    try {
      impl_->context.MakeCurrent();
      glDeleteTextures(static_cast<GLsizei>(impl_->textures.size()), impl_->textures.data());
    } catch (const Error&) {
      // The context goes away with impl_ anyway, and its textures with it.
    }
  }
}

RenderedStereoFrame SyntheticRenderer::Render(const SyntheticSequence& sequence, int frame) {
  CSLAM_CHECK(frame >= 0 && frame < sequence.num_frames(), "frame out of range");
  std::vector<Pose> objects(sequence.num_objects());
  for (int o = 0; o < sequence.num_objects(); ++o) objects[o] = sequence.world_from_object[o][frame];
  return Render(sequence.world_from_cam[frame], objects);
}

RenderedStereoFrame SyntheticRenderer::Render(const Pose& world_from_cam,
                                              const std::vector<Pose>& world_from_object) {
  CSLAM_CHECK(world_from_object.size() == impl_->bodies.size(),
              "one pose per body of the geometry is needed");
  impl_->context.MakeCurrent();
  const int k = options_.supersample;
  const Eigen::Vector3d light = options_.light_direction.normalized();

  RenderView base;
  base.fx = camera_.fx;
  base.fy = camera_.fy;
  base.cx = camera_.cx;
  base.cy = camera_.cy;
  base.width = camera_.width;
  base.height = camera_.height;
  base.near_m = 0.05;
  base.far_m = 2000.0;

  Pose right_from_left = Pose::Identity();
  right_from_left.translation() = Eigen::Vector3d(-camera_.baseline, 0, 0);
  const Pose cam_from_world = world_from_cam.inverse();

  // Shaded, textured pass of one camera. Faces are drawn from both sides (a surface seen from
  // behind still hides what is behind it); the side facing the camera decides the shading.
  auto draw_grey = [&](const Pose& view_from_world) -> cv::Mat {
    RenderView view = base;
    view.view_from_world = view_from_world;
    view = view.Scaled(k);
    glViewport(0, 0, view.width, view.height);
    const float bg = options_.background_grey / 255.0f;
    glClearColor(bg, bg, bg, 1.0f);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glDisable(GL_LIGHTING);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glShadeModel(GL_FLAT);
    glHint(GL_PERSPECTIVE_CORRECTION_HINT, GL_NICEST);
    glEnable(GL_TEXTURE_2D);
    glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
    LoadMatrix(GL_PROJECTION, view.GlProjection());
    const Eigen::Vector3d eye_in_world = view_from_world.inverse().translation();
    for (size_t o = 0; o < impl_->bodies.size(); ++o) {
      const Pose& world_from_body = world_from_object[o];
      RenderView body_view = view;
      body_view.view_from_world = view_from_world * world_from_body;
      LoadMatrix(GL_MODELVIEW, body_view.GlModelView());
      const Eigen::Vector3d eye_in_body = world_from_body.inverse() * eye_in_world;
      int bound = -1;
      for (const Impl::DrawQuad& q : impl_->bodies[o]) {
        const bool front = q.normal.dot(eye_in_body - q.corner[0]) >= 0;
        const Eigen::Vector3d n_world = world_from_body.linear() * (front ? q.normal : -q.normal);
        const double shade = options_.ambient + (1.0 - options_.ambient) * std::max(0.0, n_world.dot(light));
        const float g = static_cast<float>(std::clamp(shade * q.albedo, 0.0, 1.0));
        if (q.pool_index != bound) {
          bound = q.pool_index;
          glBindTexture(GL_TEXTURE_2D, impl_->textures[bound]);
        }
        glColor3f(g, g, g);
        glBegin(GL_QUADS);
        for (int c = 0; c < 4; ++c) {
          glTexCoord2d(q.st[c].x(), q.st[c].y());
          glVertex3d(q.corner[c].x(), q.corner[c].y(), q.corner[c].z());
        }
        glEnd();
      }
    }
    glDisable(GL_TEXTURE_2D);
    cv::Mat bgr = impl_->context.ReadPixels(), grey;
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    if (k > 1) {
      cv::Mat small;
      cv::resize(grey, small, cv::Size(camera_.width, camera_.height), 0, 0, cv::INTER_AREA);
      grey = small;
    }
    return grey;
  };

  RenderedStereoFrame out;
  out.left = draw_grey(cam_from_world);
  out.right = draw_grey(right_from_left * cam_from_world);

  // Id pass at the camera's own resolution (the id at each pixel centre, no filtering): the
  // body id as an exact colour (red = low byte, green = high byte), nothing blended or dithered.
  {
    RenderView view = base;
    view.view_from_world = cam_from_world;
    glViewport(0, 0, view.width, view.height);
    glClearColor(1.0f, 1.0f, 0.0f, 1.0f);  // = kNoObjectId
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glDisable(GL_DITHER);
    glDisable(GL_BLEND);
    glDisable(GL_TEXTURE_2D);
    glDisable(GL_POLYGON_SMOOTH);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glShadeModel(GL_FLAT);
    LoadMatrix(GL_PROJECTION, view.GlProjection());
    for (size_t o = 0; o < impl_->bodies.size(); ++o) {
      RenderView body_view = view;
      body_view.view_from_world = cam_from_world * world_from_object[o];
      LoadMatrix(GL_MODELVIEW, body_view.GlModelView());
      const unsigned id = static_cast<unsigned>(o);
      glColor3ub(static_cast<GLubyte>(id & 0xFF), static_cast<GLubyte>((id >> 8) & 0xFF), 0);
      glBegin(GL_QUADS);
      for (const Impl::DrawQuad& q : impl_->bodies[o])
        for (int c = 0; c < 4; ++c) glVertex3d(q.corner[c].x(), q.corner[c].y(), q.corner[c].z());
      glEnd();
    }
    glEnable(GL_DITHER);
    const cv::Mat bgr = impl_->context.ReadPixels();
    // With supersampling the viewport covers the bottom-left corner of the GL buffer, which is
    // the bottom-left corner of the flipped image.
    const cv::Mat roi = bgr(cv::Rect(0, bgr.rows - camera_.height, camera_.width, camera_.height));
    out.object_id.create(camera_.height, camera_.width, CV_16UC1);
    for (int y = 0; y < camera_.height; ++y) {
      const cv::Vec3b* src = roi.ptr<cv::Vec3b>(y);
      uint16_t* dst = out.object_id.ptr<uint16_t>(y);
      for (int x = 0; x < camera_.width; ++x) dst[x] = static_cast<uint16_t>(src[x][2] | (src[x][1] << 8));
    }
  }
  return out;
}

}  // namespace cslam
