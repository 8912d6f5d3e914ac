// A scene file's bodies and terrains at rest, drawn offscreen by jelly's viewer component into a
// PNG from the camera `jelly view` starts with; prints the components, where the camera puts
// the bodies' centre and the share of the picture in the first body's colour:
//   consumer_viewer SCENE.json OUT.png
#include <cstdio>
#include <string>
#include <vector>

#include <jelly/core/components.hpp>
#include <jelly/io/scene.hpp>
#include <jelly/viewer/camera.hpp>
#include <jelly/viewer/framing.hpp>
#include <jelly/viewer/image_io.hpp>
#include <jelly/viewer/offscreen.hpp>
#include <jelly/viewer/render_target.hpp>
#include <jelly/viewer/renderer.hpp>
#include <jelly/viewer/scene_builder.hpp>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: consumer_viewer SCENE.json OUT.png\n");
    return 2;
  }
  try {
    std::string names;
    for (const jelly::ComponentInfo& c : jelly::components()) names += " " + std::string(c.name);
    std::printf("components:%s\n", names.c_str());

    const jelly::Scene scene = jelly::load_scene(argv[1]);
    const jelly::Model model = jelly::make_model(scene);
    jelly::Terrains terrains;
    for (const auto& spec : scene.terrains) terrains.push_back(spec->make());
    jelly::Vec3 lo, hi;
    jelly::viewer::bounds_of(model.rest_position, lo, hi);
    const int width = 320, height = 240;
    const jelly::viewer::Camera camera =
        jelly::viewer::framing_camera(lo, hi, terrains, 0, static_cast<float>(width) / height);
    const auto centre = camera.project((0.5 * (lo + hi)).cast<float>(), width, height);
    if (centre) std::printf("centre at pixel %.0f %.0f\n", centre->x(), centre->y());

    const jelly::viewer::SceneBuilder builder(model, std::move(terrains), lo, hi);
    const jelly::viewer::OffscreenContext context;  // throws without EGL
    jelly::viewer::Renderer renderer;
    jelly::viewer::RenderTarget target(width, height);
    target.bind();
    renderer.draw(builder.make_scene(model.rest_position, 0), camera, width, height);
    target.resolve();
    std::vector<std::uint8_t> rgb;
    target.read_rgb(rgb);
    jelly::viewer::write_png(argv[2], width, height, rgb.data());
    long red = 0;
    for (size_t i = 0; i + 2 < rgb.size(); i += 3)
      red += rgb[i] > 60 && rgb[i] > rgb[i + 1] + 40 && rgb[i] > rgb[i + 2] + 30;
    std::printf("red share %.3f\n", static_cast<double>(red) / (width * height));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
