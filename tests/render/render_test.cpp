// The ray tracer: silhouettes against the analytic sphere, a textured plane that puts each colour
// where the texture says, face colours where the faces project, exact Lambert shading of a flat
// plane, the wireframe, determinism across thread counts, and input errors.
#include "elastic/render/render.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "elastic/core/error.h"
#include "elastic/image/image.h"
#include "elastic/mesh/mesh_io.h"
#include "elastic/render/camera.h"
#include "elastic/shapes/procedural_shapes.h"
#include "support.h"

namespace elastic {
namespace {

Camera head_on(int size, double fov_deg = 60.0) {
  Camera camera;
  camera.eye = {0.0, 0.0, 3.0};
  camera.target = {0.0, 0.0, 0.0};
  camera.up = {0.0, 1.0, 0.0};
  camera.fov_deg = fov_deg;
  camera.width = size;
  camera.height = size;
  return camera;
}

/// An n x n grid of unit-spaced quads covering [-1,1]^2 in z = 0, normal +z, with texture
/// coordinates u = (x+1)/2, v = (y+1)/2 and one material.
PolygonMesh grid_plane(int n) {
  PolygonMesh mesh;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const double x = -1.0 + 2.0 * i / n, y = -1.0 + 2.0 * j / n;
      mesh.positions.emplace_back(x, y, 0.0);
      mesh.texcoords.emplace_back(0.5 * (x + 1.0), 0.5 * (y + 1.0));
    }
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      mesh.add_face({a, a + 1, a + n + 2, a + n + 1});  // counter-clockwise seen from +z
    }
  }
  mesh.corner_texcoords = mesh.face_vertices;  // one texture coordinate per vertex
  return mesh;
}

/// The light factor of a surface facing the camera head-on under the default options:
/// ambient + headlight * 1 + key * (key direction . view axis), the key direction being given in
/// camera coordinates whose z points at the viewer.
float head_on_light() {
  const RenderOptions o;
  return static_cast<float>(o.ambient + o.headlight +
                            o.key_light * o.key_light_direction.normalized().z());
}

bool is_red(const Eigen::Vector4f& c) {
  return c.x() > 0.5f && c.y() < 0.1f && c.z() < 0.1f;
}
bool is_blue(const Eigen::Vector4f& c) {
  return c.z() > 0.5f && c.x() < 0.1f && c.y() < 0.1f;
}

TEST(Render, SphereCoversItsAnalyticSilhouetteAndNothingElse) {
  ShapeOptions shape;
  shape.faces = ShapeFaces::Triangles;
  shape.resolution = 48;
  Scene scene;
  scene.objects.push_back({make_sphere(shape), {}});
  scene.objects[0].look.colors = SurfaceColoring::Plain;
  scene.objects[0].look.plain_color = {0.9f, 0.1f, 0.1f};
  const Camera camera = frame_box(bounding_box(scene), {0.3, -0.2, 1.0}, 40.0, 64, 64);
  RenderOptions options;
  options.transparent_background = true;  // background is alpha 0 exactly
  const Image image = render(scene, camera, options);
  ASSERT_EQ(image.width, 64);
  ASSERT_EQ(image.height, 64);

  // The unit sphere's silhouette: the ray through (px, py) passes the centre at distance
  // |eye x d| (the centre is the origin). Vertices lie on the sphere and faces inside it, so a
  // pixel all of whose rays miss the unit ball is background; the inscribed polyhedron at this
  // resolution reaches beyond radius cos(edge angle) > 0.99, so a pixel whose rays all pass within
  // 0.97 is covered. "All rays" is checked on a 9 x 9 grid over the pixel; the 0.03 margins are
  // far wider than the ray spacing between grid points (~1/8 pixel ~ 0.004 units here).
  const CameraFrame frame = camera_frame(camera);
  int covered = 0, red = 0;
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      double nearest = 1e9, farthest = 0.0;
      for (int j = 0; j <= 8; ++j) {
        for (int i = 0; i <= 8; ++i) {
          const Eigen::Vector3d d = camera_ray_direction(camera, frame, x + i / 8.0, y + j / 8.0);
          const double distance = camera.eye.cross(d).norm();
          nearest = std::min(nearest, distance);
          farthest = std::max(farthest, distance);
        }
      }
      const Eigen::Vector4f& pixel = image.at(x, y);
      if (nearest > 1.03) {
        EXPECT_EQ(pixel.w(), 0.0f) << x << "," << y;
      }
      if (farthest < 0.97) {
        EXPECT_EQ(pixel.w(), 1.0f) << x << "," << y;
        ++covered;
        if (pixel.x() > 3.0f * pixel.y() && pixel.x() > 3.0f * pixel.z()) ++red;
      }
    }
  }
  // The framed box is wider than the sphere; its disk still has a radius of more than 12 pixels.
  EXPECT_GT(covered, 450);
  EXPECT_EQ(red, covered);  // the object's colour, shaded, everywhere on it
}

TEST(Render, TexturedPlaneShowsTheLeftHalfLeftAndTheRightHalfRight) {
  Image texture(8, 4);
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 8; ++x)
      texture.at(x, y) = x < 4 ? Eigen::Vector4f(1, 0, 0, 1) : Eigen::Vector4f(0, 0, 1, 1);
  }
  Scene scene;
  SceneObject plane{grid_plane(1), {}};
  plane.mesh.materials.push_back(Material{"decal", {0.8, 0.8, 0.8}, {}});
  plane.mesh.face_materials.assign(static_cast<size_t>(plane.mesh.num_faces()), 0);
  plane.look.textures = {texture};
  scene.objects.push_back(plane);
  const Camera camera = head_on(64);
  const Image image = render(scene, camera);

  // Where the plane's points x = -0.8 .. 0.8 land (the texture is tiled, so the outermost 1/16
  // of u blends with the other side; bilinear filtering blends within 1/16 of u = 0.5 too, i.e.
  // |x| < 0.125: skip |x| < 0.2).
  const double left = project(camera, {-0.8, 0.0, 0.0}).pixel.x();
  const double middle_left = project(camera, {-0.2, 0.0, 0.0}).pixel.x();
  const double middle_right = project(camera, {0.2, 0.0, 0.0}).pixel.x();
  const double right = project(camera, {0.8, 0.0, 0.0}).pixel.x();
  const double top = project(camera, {0.0, 0.8, 0.0}).pixel.y();
  const double bottom = project(camera, {0.0, -0.8, 0.0}).pixel.y();
  int reds = 0, blues = 0;
  for (int y = static_cast<int>(top) + 1; y < static_cast<int>(bottom); ++y) {
    for (int x = static_cast<int>(left) + 1; x < static_cast<int>(middle_left); ++x) {
      EXPECT_TRUE(is_red(image.at(x, y))) << x << "," << y;
      ++reds;
    }
    for (int x = static_cast<int>(middle_right) + 1; x < static_cast<int>(right); ++x) {
      EXPECT_TRUE(is_blue(image.at(x, y))) << x << "," << y;
      ++blues;
    }
  }
  EXPECT_GT(reds, 200);
  EXPECT_EQ(reds, blues);
}

TEST(Render, TextureFromAnObjMaterialFileLandsOnItsHalf) {
  // The file route: OBJ + MTL + PNG written, read back, the texture loaded by render() itself.
  const auto dir = test::scratch_dir("obj_texture");
  Image texture(8, 4);
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 8; ++x) {
      texture.at(x, y) = x < 4 ? Eigen::Vector4f(1, 0, 0, 1) : Eigen::Vector4f(0, 0, 1, 1);
    }
  }
  write_png(dir / "halves.png", texture);
  PolygonMesh plane = grid_plane(1);
  plane.materials.push_back(Material{"halves", {0.8, 0.8, 0.8}, dir / "halves.png"});
  plane.face_materials = {0};
  write_mesh(dir / "plane.obj", plane);
  Scene scene;
  scene.objects.push_back({read_mesh(dir / "plane.obj").mesh, {}});
  const Camera camera = head_on(32);
  const Image image = render(scene, camera);
  EXPECT_TRUE(is_red(image.at(static_cast<int>(project(camera, {-0.5, 0, 0}).pixel.x()), 16)));
  EXPECT_TRUE(is_blue(image.at(static_cast<int>(project(camera, {0.5, 0, 0}).pixel.x()), 16)));
  // Without a texture the material's Kd shows (SurfaceColoring::Materials), shaded.
  scene.objects[0].look.colors = SurfaceColoring::Materials;
  const Image plain = render(scene, camera);
  EXPECT_NEAR(plain.at(16, 16).x(), 0.8f * head_on_light(), 1e-5f);
}

TEST(Render, TextureRowsAreUpsideUp) {
  // Top row of the image file is v = 1, the plane's top (+y), which the camera shows at the top.
  Image texture(2, 2);
  texture.at(0, 0) = {1, 0, 0, 1};  // top left: red
  texture.at(1, 0) = {0, 0, 1, 1};  // top right: blue
  texture.at(0, 1) = {0, 1, 0, 1};  // bottom left: green
  texture.at(1, 1) = {1, 1, 0, 1};  // bottom right: yellow
  Scene scene;
  SceneObject plane{grid_plane(2), {}};
  plane.mesh.materials.push_back(Material{"quadrants", {0.8, 0.8, 0.8}, {}});
  plane.mesh.face_materials.assign(static_cast<size_t>(plane.mesh.num_faces()), 0);
  plane.look.textures = {texture};
  scene.objects.push_back(plane);
  const Camera camera = head_on(48);
  RenderOptions options;
  options.samples_per_pixel = 1;
  const Image image = render(scene, camera, options);
  // Texel centres are at u, v = 1/4 and 3/4, i.e. x, y = -0.5 and 0.5 on the plane: there the
  // bilinear lookup returns the texel itself.
  const auto at = [&](double x, double y) {
    const Eigen::Vector2d p = project(camera, {x, y, 0.0}).pixel;
    return image.at(static_cast<int>(p.x()), static_cast<int>(p.y()));
  };
  const float light = head_on_light();
  // One jittered ray lands within a pixel (0.054 plane units here) of the texel centre along each
  // axis, where the bilinear weights of the neighbours (texels are 1 unit wide) are at most 0.054
  // per axis: a channel is off by less than 2 x 0.054 x light < 0.1.
  EXPECT_NEAR(at(-0.5, 0.5).x(), light, 0.1f);
  EXPECT_LT(at(-0.5, 0.5).z(), 0.1f);
  EXPECT_NEAR(at(0.5, 0.5).z(), light, 0.1f);
  EXPECT_NEAR(at(-0.5, -0.5).y(), light, 0.1f);
  EXPECT_LT(at(-0.5, -0.5).x(), 0.1f);
  EXPECT_NEAR(at(0.5, -0.5).x(), light, 0.1f);
  EXPECT_NEAR(at(0.5, -0.5).y(), light, 0.1f);
}

TEST(Render, FaceColoursAppearWhereTheirFacesProjectWithLambertShading) {
  Scene scene;
  SceneObject plane{grid_plane(3), {}};
  for (int f = 0; f < plane.mesh.num_faces(); ++f) {
    plane.mesh.face_colors.emplace_back(0.1f * f, 1.0f - 0.1f * f, 0.5f);
  }
  plane.look.colors = SurfaceColoring::FaceColors;
  scene.objects.push_back(plane);
  const Camera camera = head_on(64);
  const Image image = render(scene, camera);
  // A flat plane facing the camera has the same light factor everywhere (the headlight and key
  // light are directional): pixel = colour * light, up to float rounding of a few products.
  const float light = head_on_light();
  for (int f = 0; f < plane.mesh.num_faces(); ++f) {
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (int v : plane.mesh.face(f)) centroid += plane.mesh.positions[v] / 4.0;
    const Eigen::Vector2d p = project(camera, centroid).pixel;
    const Eigen::Vector4f& pixel = image.at(static_cast<int>(p.x()), static_cast<int>(p.y()));
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(pixel[c], std::min(1.0f, plane.mesh.face_colors[f][c] * light), 1e-5f)
          << "face " << f << " channel " << c;
    }
  }
}

TEST(Render, WireframeDarkensTheEdgesOfAGridLyingOnASurface) {
  Scene scene;
  SceneObject plane{grid_plane(1), {}};
  plane.look.colors = SurfaceColoring::Plain;
  plane.look.plain_color = {1.0f, 1.0f, 1.0f};
  SceneObject grid{grid_plane(4), {}};
  grid.look.surface = false;
  grid.look.wireframe = true;
  grid.look.wire_width_px = 2.0;
  grid.look.wire_color = {0.0f, 0.0f, 0.0f};
  scene.objects = {plane, grid};
  const Camera camera = head_on(64);
  const Image image = render(scene, camera);
  const auto luminance = [&](double x, double y) {
    const Eigen::Vector2d p = project(camera, {x, y, 0.0}).pixel;
    const Eigen::Vector4f c = image.at(static_cast<int>(p.x()), static_cast<int>(p.y()));
    return (c.x() + c.y() + c.z()) / 3.0f;
  };
  // Grid lines at x, y = -0.5, 0, 0.5; cell centres at +-0.25, +-0.75.
  const float face = luminance(0.25, 0.25);
  EXPECT_GT(face, 0.8f);  // white surface, lit head-on
  for (double t : {-0.5, 0.0, 0.5}) {
    EXPECT_LT(luminance(t, 0.25), 0.5f * face) << "vertical line at x = " << t;
    EXPECT_LT(luminance(0.75, t), 0.5f * face) << "horizontal line at y = " << t;
  }
}

TEST(Render, AGridJustUnderASurfaceShowsAndOneFarBelowIsHidden) {
  // A grid 0.5% of the scene diagonal (2.83) under a white plane is within the default 1%
  // tolerance; one 0.3 units under (10%) is hidden by the plane.
  const auto luminance_on_line = [](double depth) {
    Scene scene;
    SceneObject plane{grid_plane(1), {}};
    plane.look.colors = SurfaceColoring::Plain;
    plane.look.plain_color = {1.0f, 1.0f, 1.0f};
    SceneObject grid{grid_plane(4), {}};
    for (Eigen::Vector3d& p : grid.mesh.positions) p.z() = -depth;
    grid.look.surface = false;
    grid.look.wireframe = true;
    grid.look.wire_width_px = 2.0;
    grid.look.wire_color = {0.0f, 0.0f, 0.0f};
    scene.objects = {plane, grid};
    const Camera camera = head_on(64);
    const Image image = render(scene, camera);
    const Eigen::Vector2d p = project(camera, {0.0, 0.25, 0.0}).pixel;  // on the line x = 0
    const Eigen::Vector4f c = image.at(static_cast<int>(p.x()), static_cast<int>(p.y()));
    return (c.x() + c.y() + c.z()) / 3.0f;
  };
  EXPECT_LT(luminance_on_line(0.014), 0.1f);  // the black wire
  EXPECT_GT(luminance_on_line(0.3), 0.8f);    // the white plane
}

TEST(Render, VertexColoursAreInterpolated) {
  Scene scene;
  SceneObject plane{grid_plane(1), {}};
  // Colour linear in x: red at x = -1, green at x = +1. Bilinear on the quad's two triangles
  // equals the linear function, so the colour at any x is exact.
  for (const Eigen::Vector3d& p : plane.mesh.positions) {
    const auto t = static_cast<float>(0.5 * (p.x() + 1.0));
    plane.mesh.vertex_colors.emplace_back(1.0f - t, t, 0.0f);
  }
  scene.objects.push_back(plane);
  const Camera camera = head_on(64);
  RenderOptions options;
  options.samples_per_pixel = 1;
  const Image image = render(scene, camera, options);
  const float light = head_on_light();
  for (double x : {-0.6, 0.0, 0.6}) {
    const Eigen::Vector2d p = project(camera, {x, 0.1, 0.0}).pixel;
    const Eigen::Vector4f& c = image.at(static_cast<int>(p.x()), static_cast<int>(p.y()));
    // The jittered ray is within a pixel (0.06 plane units: 0.03 in t) of the projected point.
    const auto t = static_cast<float>(0.5 * (x + 1.0));
    EXPECT_NEAR(c.x(), (1.0f - t) * light, 0.03f);
    EXPECT_NEAR(c.y(), t * light, 0.03f);
  }
}

TEST(Render, IsDeterministicWhateverTheThreadCount) {
  ShapeOptions shape;
  shape.resolution = 16;
  Scene scene;
  scene.objects.push_back({make_torus(shape), {}});
  scene.objects[0].look.wireframe = true;
  const Camera camera = frame_box(bounding_box(scene), view_from_angles(30, 40), 40.0, 48, 40);
  RenderOptions options;
  options.ambient_occlusion_samples = 4;  // random rays, too
  options.threads = 1;
  const Image one = render(scene, camera, options);
  options.threads = 2;
  const Image two = render(scene, camera, options);
  options.threads = 0;
  const Image all = render(scene, camera, options);
  EXPECT_TRUE(one.pixels == two.pixels);
  EXPECT_TRUE(one.pixels == all.pixels);
  // The seed matters (so the test above compares random streams, not constants).
  options.seed = 2;
  const Image other = render(scene, camera, options);
  EXPECT_FALSE(one.pixels == other.pixels);
}

// Adaptive antialiasing against every pixel traced with all its rays (threshold 0), on a scene
// with everything that makes edges: a sphere's silhouette over the background, per-face colours
// (a random heatmap, so neighbouring faces differ), and a wireframe thinner than a pixel lying on
// the surface, whose tubes centre rays mostly miss. Pixels the wires darken, and silhouette pixels,
// must be the full computation bit for bit; elsewhere the picture stays within a few levels.
TEST(Render, AdaptiveAntialiasingKeepsEdgesAndThinWiresExactly) {
  ShapeOptions shape;
  shape.faces = ShapeFaces::Quads;
  shape.resolution = 12;
  SceneObject sphere{make_sphere(shape), {}};
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.2f, 0.9f);
  for (int f = 0; f < sphere.mesh.num_faces(); ++f) {
    sphere.mesh.face_colors.emplace_back(u(rng), u(rng), u(rng));
  }
  sphere.look.colors = SurfaceColoring::FaceColors;
  ShapeOptions grid_shape = shape;
  grid_shape.resolution = 7;  // its edges cross the coloured faces rather than follow their sides
  SceneObject grid{make_sphere(grid_shape), {}};
  grid.look.surface = false;
  grid.look.wireframe = true;
  grid.look.wire_width_px = 0.15;
  grid.look.wire_color = {0.0f, 0.0f, 0.0f};
  Scene scene;
  scene.objects = {sphere, grid};
  const Camera camera = frame_box(bounding_box(scene), {0.3, -0.2, 1.0}, 40.0, 160, 160);
  RenderOptions options;
  options.transparent_background = true;  // silhouette pixels: alpha strictly between 0 and 1
  RenderOptions full_options = options;
  full_options.adaptive_threshold = 0.0;
  const Image full = render(scene, camera, full_options);
  const Image adaptive = render(scene, camera, options);
  scene.objects.pop_back();
  const Image no_wires = render(scene, camera, full_options);

  int wire_pixels = 0, edge_pixels = 0, differing = 0;
  double sum = 0.0;
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      const Eigen::Vector4f& f = full.at(x, y);
      const Eigen::Vector4f& a = adaptive.at(x, y);
      const float darkened = (no_wires.at(x, y) - f).head<3>().maxCoeff();
      if (darkened > 0.02f) {
        ++wire_pixels;
        EXPECT_EQ(a, f) << "wire pixel " << x << "," << y;
      }
      if (f.w() > 0.0f && f.w() < 1.0f) {
        ++edge_pixels;
        EXPECT_EQ(a, f) << "silhouette pixel " << x << "," << y;
      }
      const float d = (a - f).cwiseAbs().maxCoeff();
      sum += static_cast<double>(d);
      differing += d > 0.0f ? 1 : 0;
      EXPECT_LT(d, 0.12f) << x << "," << y;
    }
  }
  EXPECT_GT(wire_pixels, 100);  // the wires show in the full picture
  EXPECT_GT(edge_pixels, 100);
  EXPECT_GT(differing, 300);  // the adaptive picture is not just the full one
  EXPECT_LT(sum / (camera.width * camera.height), 2.0 / 255.0);
}

TEST(Render, WritesAPngThatReadsBack) {
  Scene scene;
  scene.objects.push_back({make_cap(), {}});
  const Camera camera =
      frame_box(bounding_box(scene), vector_area(scene.objects[0].mesh), 40, 32, 24);
  const Image image = render(scene, camera);
  const auto path = test::scratch_dir("render") / "cap.png";
  write_png(path, image);
  const Image back = read_image(path);
  ASSERT_EQ(back.width, 32);
  ASSERT_EQ(back.height, 24);
  // 8-bit quantisation: half a step.
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    EXPECT_LE((back.pixels[i] - image.pixels[i]).cwiseAbs().maxCoeff(), 0.5f / 255.0f + 1e-6f);
  }
}

TEST(Render, VectorAreaOfAPlaneAndOfAClosedSurface) {
  const Eigen::Vector3d plane = vector_area(grid_plane(3));
  EXPECT_NEAR((plane - Eigen::Vector3d(0, 0, 4)).norm(), 0.0, 1e-12);  // area 4, normal +z
  EXPECT_LT(vector_area(make_sphere()).norm(), 1e-9);
}

TEST(Render, RejectsInconsistentInput) {
  const Camera camera = head_on(8);
  Scene scene;
  scene.objects.push_back({grid_plane(1), {}});
  scene.objects[0].look.colors = SurfaceColoring::FaceColors;  // the mesh has none
  EXPECT_THROW(render(scene, camera), InvalidInputError);
  scene.objects[0].look.colors = SurfaceColoring::Texture;  // no material
  EXPECT_THROW(render(scene, camera), InvalidInputError);
  scene.objects[0].look.colors = SurfaceColoring::Auto;
  scene.objects[0].mesh.face_vertices[2] = 99;  // out of range
  EXPECT_THROW(render(scene, camera), InvalidInputError);
  scene.objects[0].mesh = grid_plane(1);
  RenderOptions options;
  options.samples_per_pixel = 0;
  EXPECT_THROW(render(scene, camera, options), InvalidInputError);
  options = {};
  options.adaptive_threshold = 1.5;
  EXPECT_THROW(render(scene, camera, options), InvalidInputError);
  options.adaptive_threshold = std::nan("");
  EXPECT_THROW(render(scene, camera, options), InvalidInputError);
  // A texture file that is not there: read_image's error, naming the file.
  scene.objects[0].mesh.materials.push_back(Material{"m", {1, 1, 1}, "/nonexistent/texture.png"});
  scene.objects[0].mesh.face_materials = {0};
  try {
    render(scene, camera);
    ADD_FAILURE() << "no error for a missing texture";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("texture.png"), std::string::npos);
  }
  const MaterialTextures textures = load_material_textures(scene.objects[0].mesh);
  ASSERT_EQ(textures.images.size(), 1u);
  EXPECT_TRUE(textures.images[0].empty());
  EXPECT_EQ(textures.warnings.size(), 1u);
}

}  // namespace
}  // namespace elastic
