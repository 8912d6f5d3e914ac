// The renderer offscreen (EGL, no display needed): the seed jelly is drawn where the camera
// projects its particles, particles and springs draw without OpenGL errors, PNG round trips,
// and `jelly render` writes the frames ffprobe counts.
#include <gtest/gtest.h>

#include <memory>
#include <stdexcept>

#include <jelly/geometry/cube.hpp>
#include <jelly/io/scene.hpp>
#include <jelly/viewer/detail/gl.hpp>
#include <jelly/viewer/image_io.hpp>
#include <jelly/viewer/offscreen.hpp>
#include <jelly/viewer/render_target.hpp>
#include <jelly/viewer/renderer.hpp>
#include <jelly/viewer/scene_builder.hpp>

#include "viewer/viewer_support.hpp"

namespace jelly {
namespace {

using testing::TempDir;

class Offscreen : public ::testing::Test {
 protected:
  void SetUp() override {
    try {
      context_ = std::make_unique<viewer::OffscreenContext>();
    } catch (const std::runtime_error& e) {
      GTEST_SKIP() << "no offscreen OpenGL here: " << e.what();
    }
  }
  std::unique_ptr<viewer::OffscreenContext> context_;
};

struct SeedView {
  Scene scene = load_scene(JELLY_SCENES_DIR "/seed_slope.json");
  Model model = make_model(scene);
  std::unique_ptr<viewer::SceneBuilder> builder;
  viewer::Camera camera;
  SeedView() {
    Terrains terrains;
    for (const auto& t : scene.terrains) terrains.push_back(t->make());
    Vec3 lo, hi;
    viewer::bounds_of(model.rest_position, lo, hi);
    builder = std::make_unique<viewer::SceneBuilder>(model, std::move(terrains), lo, hi);
    camera.parse("-20,18,25,0,6,0");
  }
};

std::vector<std::uint8_t> draw(viewer::Renderer& renderer, const viewer::RenderScene& scene,
                               const viewer::Camera& camera, int w, int h) {
  viewer::RenderTarget target(w, h, 4);
  target.bind();
  renderer.draw(scene, camera, w, h);
  target.resolve();
  std::vector<std::uint8_t> rgb;
  target.read_rgb(rgb);
  return rgb;
}

TEST_F(Offscreen, SeedJellyIsWhereTheCameraProjectsIt) {
  SeedView v;
  const int w = 480, h = 360;
  viewer::Renderer renderer;
  const viewer::RenderScene scene = v.builder->make_scene(v.model.rest_position, 0);
  const std::vector<std::uint8_t> rgb = draw(renderer, scene, v.camera, w, h);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
  const testing::Box box = testing::projected_box(v.camera, v.model.rest_position, w, h);
  ASSERT_GT(box.x0, 0);
  ASSERT_LT(box.x1, w);
  ASSERT_GT(box.y0, 0);
  ASSERT_LT(box.y1, h);
  const testing::JellyPixels c = testing::count_jelly(rgb, w, h, box);
  EXPECT_GT(c.fraction(), 0.6) << c.inside << " of " << c.box_pixels;
  EXPECT_EQ(c.outside, 0);
}

TEST_F(Offscreen, ParticlesSpringsAndDragDrawWithoutErrors) {
  SeedView v;
  viewer::Renderer renderer;
  viewer::RenderScene scene = v.builder->make_scene(v.model.rest_position, 0);
  scene.show_surfaces = false;
  scene.show_particles = true;
  scene.show_springs = true;
  scene.show_structural_only = false;
  scene.spring_coloring = viewer::SpringColoring::kStrain;
  scene.drag = true;
  scene.drag_to = Eigen::Vector3f(3, 9, 0);
  const std::vector<std::uint8_t> rgb = draw(renderer, scene, v.camera, 320, 240);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
  // Springs at rest are white under the strain colouring, particles the jelly's red: both show.
  long red = 0, white = 0;
  for (size_t i = 0; i < rgb.size(); i += 3) {
    red += testing::is_jelly(&rgb[i]);
    white += rgb[i] > 225 && rgb[i + 1] > 225 && rgb[i + 2] > 225;
  }
  EXPECT_GT(red, 100);
  EXPECT_GT(white, 100);
}

TEST_F(Offscreen, PngRoundTrip) {
  TempDir dir;
  std::vector<std::uint8_t> rgb(7 * 5 * 3);
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<std::uint8_t>(i * 7);
  viewer::write_png(dir.file("a.png"), 7, 5, rgb.data());
  const viewer::Image image = viewer::read_png(dir.file("a.png"));
  EXPECT_EQ(image.width, 7);
  EXPECT_EQ(image.height, 5);
  EXPECT_EQ(image.rgb, rgb);
}

// `jelly render`: mp4, gif and PNG frames with the frame count and size ffprobe reports.
TEST(RenderCli, WritesVideosFfprobeConfirms) {
  TempDir dir;
  if (std::system("command -v ffprobe >/dev/null 2>&1") != 0) GTEST_SKIP() << "no ffprobe";
  const std::string jelly = std::string("'") + JELLY_CLI + "' ";
  testing::Result r = testing::run(jelly +
                                       "run '" JELLY_SCENES_DIR
                                       "/seed_slope.json' "
                                       "--duration 0.25 --quiet -o '" +
                                       dir.file("r.h5") + "'",
                                   dir);
  ASSERT_EQ(r.code, 0) << r.err;
  for (const std::string out : {"v.mp4", "v.gif"}) {
    r = testing::run(jelly + "render '" + dir.file("r.h5") + "' -o '" + dir.file(out) +
                         "' --width 160 --height 120 --samples 1",
                     dir);
    ASSERT_EQ(r.code, 0) << r.err;
    if (r.err.find("no offscreen") != std::string::npos) GTEST_SKIP() << r.err;
    r = testing::run(
        "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
        "stream=width,height,nb_read_frames -of csv=p=0 '" +
            dir.file(out) + "'",
        dir);
    EXPECT_EQ(r.out, "160,120,16\n") << out << ": " << r.err;
  }
  std::filesystem::create_directory(dir.file("frames"));
  r = testing::run(jelly + "render '" + dir.file("r.h5") + "' -o '" + dir.file("frames") +
                       "/%03d.png' --width 160 --height 120 --start 0.1",
                   dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir.file("frames/000.png")));
  EXPECT_TRUE(std::filesystem::exists(dir.file("frames/009.png")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("frames/010.png")));
  // An existing output is kept unless --overwrite.
  r = testing::run(jelly + "render '" + dir.file("r.h5") + "' -o '" + dir.file("v.mp4") +
                       "' --width 160 --height 120",
                   dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--overwrite"), std::string::npos) << r.err;
  r = testing::run(jelly + "render '" + dir.file("r.h5") + "' -o '" + dir.file("v.mp4") +
                       "' --width 160 --height 120 --end 0 --overwrite",
                   dir);
  EXPECT_EQ(r.code, 0) << r.err;
  // Bad outputs and sizes are input errors.
  for (const std::string bad :
       {"-o x.avi", "-o 'f%d%d.png'", "-o v.mp4 --width 161", "-o '/nonexistent/dir/v.mp4'"}) {
    r = testing::run(jelly + "render '" + dir.file("r.h5") + "' " + bad, dir);
    EXPECT_EQ(r.code, 2) << bad << ": " << r.err;
  }
}

}  // namespace
}  // namespace jelly
