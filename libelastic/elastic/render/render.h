#pragma once
/// \file
/// `render`: an Embree ray tracer for preview pictures of polygon meshes (the target with a pasted
/// feature, a distortion heatmap, the particle grid over the surface).
///
/// What it draws:
/// - Every object's polygons, fan-triangulated (corner 0, k, k+1), coloured by its `ObjectLook`:
///   per-face colours (a heatmap), per-vertex colours (interpolated), a texture per material
///   (OBJ `map_Kd`, sampled bilinearly at the interpolated corner texture coordinates, tiled like
///   OBJ; a texel's alpha blends it over the material's `Kd`), the materials' `Kd`, or one colour.
/// - Optionally the object's polygon edges (not the fan diagonals) as a wireframe overlay. Edges
///   are Embree round linear curves (tubes) whose radius is chosen so that they are `wire_width_px`
///   pixels wide at the distance of the camera target. They are traced in a scene of their own: a
///   wire is drawn when it is in front of the surface the ray sees or less than
///   `RenderOptions::wire_depth_tolerance` behind it, so a grid lying on (or just under) a surface
///   shows whole while surfaces well in front hide it. An object with `surface = false` shows only
///   its edges (how the particle grid is drawn over the target).
///
/// Shading: both sides of a polygon are lit alike (the normal is flipped to face the ray). Lambert
/// with smooth normals (area-weighted averages of the polygons' Newell normals at the vertices,
/// interpolated), a headlight at the eye and a key light fixed in camera space, plus an ambient
/// term; optional ambient occlusion (cosine-weighted rays, radius relative to the scene). Colours
/// are used as stored (sRGB-encoded values, no colour management, as image/image.h). Antialiasing
/// takes `samples_per_pixel` jittered rays per pixel (stratified on a k x k grid when the count is
/// a square), averaged with premultiplied alpha, where a first ray through the pixel centres finds
/// an edge, a colour change or a wire (`RenderOptions::adaptive_threshold`); elsewhere one ray.
///
/// Determinism: every random number comes from a counter-based hash of (seed, pixel, sample, use),
/// never from a shared generator, and every pixel is computed by exactly one task, so the image is
/// bit-identical for the same inputs and seed whatever the number of threads.
///
/// Precision: Embree works in single precision; vertices are shifted by the scene's bounding-box
/// centre before conversion so scenes far from the origin keep their relative precision.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "elastic/image/image.h"
#include "elastic/mesh/polygon_mesh.h"
#include "elastic/render/camera.h"

namespace elastic {

/// Which attribute of an object's mesh colours its surface.
enum class SurfaceColoring {
  Auto,          ///< Texture if any face has a textured material and the mesh has texture
                 ///< coordinates, else FaceColors, else VertexColors, else Materials, else Plain
  FaceColors,    ///< PolygonMesh::face_colors (e.g. a per-face distortion heatmap)
  VertexColors,  ///< PolygonMesh::vertex_colors, interpolated across faces
  Texture,       ///< each face's material texture at the corner texture coordinates
  Materials,     ///< each face's material `Kd` (faces without a material get `plain_color`)
  Plain          ///< `plain_color` everywhere
};

/// How one object looks.
struct ObjectLook {
  /// Which attribute colours the surface; a forced source the mesh lacks is an error.
  SurfaceColoring colors = SurfaceColoring::Auto;
  /// The colour of SurfaceColoring::Plain and of faces that have no colour under the chosen source.
  Eigen::Vector3f plain_color{0.75f, 0.76f, 0.78f};
  /// One image per entry of PolygonMesh::materials (an empty Image for a material without one).
  /// When this vector is empty, render() reads the materials' `diffuse_texture` files itself.
  std::vector<Image> textures;
  /// Draw the polygons (false: draw only the wireframe, e.g. a particle grid over another object).
  bool surface = true;
  /// Draw the polygon edges as tubes.
  bool wireframe = false;
  /// Colour of the edges.
  Eigen::Vector3f wire_color{0.08f, 0.09f, 0.12f};
  /// Edge tube diameter in pixels at the distance of the camera target, > 0.
  double wire_width_px = 1.5;
};

struct SceneObject {
  PolygonMesh mesh;
  ObjectLook look;
};

/// What to draw: objects in world coordinates (a copy of each mesh, so the scene owns its data).
struct Scene {
  std::vector<SceneObject> objects;
};

struct RenderOptions {
  /// Jittered rays per pixel (antialiasing), 1..256. A square count is stratified.
  int samples_per_pixel = 4;
  /// Adaptive antialiasing, in [0, 1]: one ray goes through every pixel's centre first, and only a
  /// pixel where that ray or a neighbour's (8-connected) sees another object (or the background),
  /// where their colours differ by more than this in a channel (0..1 after lighting, alpha
  /// premultiplied), or within about a pixel of a wireframe edge gets all `samples_per_pixel` rays
  /// (computed exactly as without adaptivity); elsewhere the centre ray is the pixel. 0: every
  /// pixel gets all rays. At the default, 4 / 255, `bash scripts/demo`'s previews trace all rays
  /// through 4% of the pixels of the textured target, 14-18% of the heatmaps' and 27% of the grid
  /// pictures'. A one-ray pixel differs from its full average by about the colour change across
  /// it, which its neighbours' centres bound unless an edge passes between them unseen.
  double adaptive_threshold = 4.0 / 255.0;
  /// Ambient-occlusion rays per surface hit (0: none), 0..256.
  int ambient_occlusion_samples = 0;
  /// Ambient-occlusion ray length as a fraction of the scene's bounding-box diagonal, > 0.
  double ambient_occlusion_radius = 0.2;
  /// Seed of the jitter and the occlusion rays; same seed, same image.
  std::uint64_t seed = 1;
  /// Background: a vertical gradient from the top colour to the bottom colour.
  Eigen::Vector3f background_top{0.93f, 0.95f, 0.98f};
  Eigen::Vector3f background_bottom{0.70f, 0.74f, 0.80f};
  /// Leave the background transparent (alpha 0) instead of drawing the gradient.
  bool transparent_background = false;
  /// Light intensities: ambient, the headlight at the eye, and the key light; their sum is the
  /// brightness of a surface facing both lights (1 keeps a white surface at white).
  double ambient = 0.2;
  double headlight = 0.5;
  double key_light = 0.35;
  /// Direction towards the key light in camera coordinates (x right, y up, z towards the viewer):
  /// by default from the upper left, in front.
  Eigen::Vector3d key_light_direction{-0.5, 0.8, 0.6};
  /// How far behind the surface seen along a ray a wire may be and still be drawn, as a fraction
  /// of the scene's bounding-box diagonal, >= 0. A particle grid's points lie on the smooth limit
  /// surface, which lies slightly inside the control mesh's convex parts: drawn over the control
  /// mesh, its edges would be hidden without this slack.
  double wire_depth_tolerance = 0.01;
  /// Worker threads (0: all the task scheduler offers). Does not change the image.
  int threads = 0;
};

/// Renders the scene as `camera.width` x `camera.height` RGBA pixels (alpha 1 unless the
/// background is transparent). Textures not given in the looks are read from the materials'
/// files.
/// \throws InvalidInputError ("render: object k: ...") for an inconsistent mesh (indices out of
///         range, attribute arrays of the wrong size, non-finite positions), a forced colour
///         source the mesh lacks, or options out of range; ("camera") for a bad camera;
///         IoError / InvalidInputError from read_image for an unreadable texture; Error when
///         Embree fails.
Image render(const Scene& scene, const Camera& camera, const RenderOptions& options = {});

/// The textures of a mesh's materials, for ObjectLook::textures: one image per material (empty
/// where the material has none or its file cannot be read or has more pixels than
/// `read_options.max_pixels`; those files are listed in `warnings`, "<file>: <problem>").
struct MaterialTextures {
  std::vector<Image> images;
  std::vector<std::string> warnings;
};
MaterialTextures load_material_textures(const PolygonMesh& mesh,
                                        const ImageReadOptions& read_options = {});

/// The bounding box of a mesh's vertices (empty for a mesh without vertices).
Eigen::AlignedBox3d bounding_box(const PolygonMesh& mesh);
/// The bounding box of every vertex of the scene.
Eigen::AlignedBox3d bounding_box(const Scene& scene);

/// The vector area: half the sum of the polygons' Newell normals (sum of p_i x p_i+1 over each
/// polygon's corners), so its length is the area of a flat mesh and its direction is where the
/// mesh mostly faces; zero for a closed mesh. Its direction is the default view of a region.
Eigen::Vector3d vector_area(const PolygonMesh& mesh);

}  // namespace elastic
