// docs/render.md quotes the part between the [example] markers: the built-in emblem as a texture on
// a plane, the edges of a grid drawn over it, framed automatically, next to the emblem itself.
// Built and run by the tests (docs.example.render_emblem_decal).
#include <Eigen/Core>
#include <filesystem>
#include <iostream>

#include "elastic/image/emblem.h"
#include "elastic/image/image.h"
#include "elastic/render/camera.h"
#include "elastic/render/compose.h"
#include "elastic/render/render.h"
#include "elastic/shapes/procedural_shapes.h"

int main() {
  // [example]
  // The square [-1,1]^2 carrying the emblem (u = (x+1)/2, v = (y+1)/2).
  elastic::PolygonMesh plane;
  plane.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  plane.texcoords = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  plane.add_face({0, 1, 2, 3});
  plane.corner_texcoords = {0, 1, 2, 3};
  plane.materials.push_back({"emblem", {0.8, 0.8, 0.8}, {}});
  plane.face_materials = {0};

  elastic::Scene scene;
  elastic::SceneObject decal{plane, {}};
  decal.look.textures = {elastic::make_emblem(256)};  // one image per material
  scene.objects.push_back(decal);
  elastic::SceneObject grid{elastic::make_plane({.resolution = 8}), {}};
  grid.look.surface = false;  // only its edges, over the decal
  grid.look.wireframe = true;
  scene.objects.push_back(grid);

  // Seen from the front (+z, where the plane faces), a little from below and the side.
  const Eigen::Vector3d view(0.3, -0.6, 1.0);
  const elastic::Camera camera =
      elastic::frame_box(elastic::bounding_box(scene), view, 35.0, 320, 240);
  const elastic::Image picture = elastic::render(scene, camera);
  const elastic::Image sheet =
      elastic::side_by_side({elastic::make_emblem(240), picture}, {"emblem", "rendered"});
  const auto path = std::filesystem::temp_directory_path() / "elastic_render_example.png";
  elastic::write_png(path, sheet);
  // [example]
  std::cout << path.string() << ": " << sheet.width << " x " << sheet.height << '\n';
  return 0;
}
