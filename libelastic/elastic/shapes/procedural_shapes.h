#pragma once
/// \file
/// Procedural control meshes of the surfaces the ElasticPaint paper maps between (plane, cylinder, torus,
/// vase, goblet, cap) plus a sphere, as triangle or quad meshes. They are the project's own test and demo
/// data (`elastic shapes` writes them into meshes/). Every shape is consistently oriented with normals
/// pointing outward (away from the axis for surfaces of revolution, +z for the plane), manifold, one
/// component, and open where the shape is open. Dimensions are in the shape's documentation below;
/// `scale` multiplies them.
///
/// Note: these are *control meshes*. The limit surface of a subdivision control mesh lies slightly inside
/// its convex parts, increasingly little as the resolution grows.

#include <string>
#include <string_view>
#include <vector>

#include "elastic/mesh/polygon_mesh.h"

namespace elastic {

enum class ShapeFaces { Triangles, Quads };

struct ShapeOptions {
  /// Triangles (for Loop) or quads (for Catmull-Clark).
  ShapeFaces faces = ShapeFaces::Quads;
  /// Segments around the axis (surfaces of revolution), or along each side (plane, sphere cube faces).
  /// The other direction gets a proportional count. 3..4096.
  int resolution = 32;
  /// Uniform scale applied to the documented dimensions.
  double scale = 1.0;
};

/// The names make_shape accepts: "plane", "cylinder", "torus", "vase", "goblet", "cap", "sphere".
const std::vector<std::string>& shape_names();

/// Builds a named shape. \throws InvalidInputError for an unknown name or out-of-range options.
PolygonMesh make_shape(std::string_view name, const ShapeOptions& options = {});

/// Square [-1,1]^2 in the plane z = 0, normal +z, one boundary loop.
PolygonMesh make_plane(const ShapeOptions& options = {});
/// Open tube: radius 0.5 around the z axis, z in [-1,1], two boundary loops.
PolygonMesh make_cylinder(const ShapeOptions& options = {});
/// Closed torus around the z axis: major radius 1, minor radius 0.35, genus 1.
PolygonMesh make_torus(const ShapeOptions& options = {});
/// Vase: surface of revolution around z with a closed bottom and an open mouth (one boundary loop);
/// radius profile documented in the .cpp.
PolygonMesh make_vase(const ShapeOptions& options = {});
/// Goblet: cup, stem and foot as one surface of revolution, open at the cup's rim (one boundary loop).
PolygonMesh make_goblet(const ShapeOptions& options = {});
/// Cap: spherical cap of the unit sphere, polar angle 0..75 degrees around +z, one boundary loop.
PolygonMesh make_cap(const ShapeOptions& options = {});
/// Closed unit sphere (quads: a cube projected onto the sphere; triangles: a subdivided icosahedron).
PolygonMesh make_sphere(const ShapeOptions& options = {});

}  // namespace elastic
