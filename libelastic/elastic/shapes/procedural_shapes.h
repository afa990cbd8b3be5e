#pragma once
/// \file
/// Procedural control meshes of the surfaces the ElasticPaint paper maps between (plane, cylinder,
/// torus, vase, goblet, cap) plus a sphere, as triangle or quad meshes. They are the project's own
/// test and demo data (`elastic shapes` writes them into meshes/). Every shape is consistently
/// oriented with normals pointing outward (away from the axis for surfaces of revolution, +z for
/// the plane), manifold, one component, and open where the shape is open. Dimensions are in the
/// shape's documentation below; `scale` multiplies them.
///
/// Triangle versions are triangulated for themselves (rings offset by half a step, bands stitched
/// for the best smallest angle; the plane splits its squares along one diagonal, which makes it a
/// regular valence-6 Loop mesh). Quad versions close a pole (vase bottom, cap top, goblet foot
/// centre) with a "quad disk": an (n/4) x (n/2 - n/4) grid of quads mapped onto the disk around the
/// pole, whose boundary is a ring of n vertices, so all faces are quads and the only extraordinary
/// vertices are the grid's 4 corners (valence 3). An odd n cannot bound an all-quad disk; then the
/// pole is one n-gon.
///
/// Note: these are *control meshes*. The limit surface of a subdivision control mesh lies slightly
/// inside its convex parts, increasingly little as the resolution grows.

#include <string>
#include <string_view>
#include <vector>

#include "elastic/mesh/polygon_mesh.h"

namespace elastic {

enum class ShapeFaces { Triangles, Quads };

struct ShapeOptions {
  /// Triangles (for Loop) or quads (for Catmull-Clark).
  ShapeFaces faces = ShapeFaces::Quads;
  /// Segments around the z axis (surfaces of revolution, and the sphere's equator), or along each
  /// side (plane). Along the profile, rings are spaced so that faces are nearly square (quads) or
  /// nearly equilateral (triangles). 3..4096.
  int resolution = 32;
  /// Uniform scale applied to the documented dimensions; finite and > 0.
  double scale = 1.0;
};

/// The names make_shape accepts: "plane", "cylinder", "torus", "vase", "goblet", "cap", "sphere".
const std::vector<std::string>& shape_names();

/// Builds a named shape. \throws InvalidInputError for an unknown name (input: the name) or
/// out-of-range options (input: "resolution", "scale" or "faces").
PolygonMesh make_shape(std::string_view name, const ShapeOptions& options = {});

/// Square [-1,1]^2 in the plane z = 0, normal +z, one boundary loop.
PolygonMesh make_plane(const ShapeOptions& options = {});
/// Open tube: radius 0.5 around the z axis, z in [-1,1], two boundary loops.
PolygonMesh make_cylinder(const ShapeOptions& options = {});
/// Closed torus around the z axis: major radius 1, minor radius 0.35, genus 1.
PolygonMesh make_torus(const ShapeOptions& options = {});
/// Vase: surface of revolution around z, z in [0, 1.52], with a closed, nearly flat bottom (centre
/// at the origin), a bulging body (radius 0.55 at z ~ 0.45), a neck (radius 0.22 at z ~ 1.2-1.3)
/// and a flared lip (radius 0.34 at the mouth, z = 1.52), the only boundary loop. Profile in the
/// .cpp.
PolygonMesh make_vase(const ShapeOptions& options = {});
/// Goblet: foot, stem and cup as one open surface of revolution around z, z in [0, 1.55]: the
/// foot's underside (closed at its centre, raised to z = 0.03) out to radius 0.53, a rounded edge
/// ~0.08 thick, a stem of radius 0.06, and a single-sheet cup (radius 0.49 at z ~ 1.2) whose rim
/// (radius 0.44, z = 1.55) is the only boundary loop. Profile in the .cpp.
PolygonMesh make_goblet(const ShapeOptions& options = {});
/// Cap: spherical cap of the unit sphere, polar angle 0..75 degrees around +z, one boundary loop.
PolygonMesh make_cap(const ShapeOptions& options = {});
/// Closed unit sphere. Quads: a cube with N = round(resolution / 4) segments per edge (so the
/// equator has about `resolution` segments), equal-angle spacing, projected. Triangles: an
/// icosahedron with each edge split into k = round(resolution * atan(2) / (2 pi)) (a great circle
/// crosses ~5.7 icosahedron edges), projected.
PolygonMesh make_sphere(const ShapeOptions& options = {});

}  // namespace elastic
