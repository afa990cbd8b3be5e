#pragma once
/// \file
/// Internal to regions/: the sides of a `points:` polygon, each the exact shortest path between
/// two consecutive corners on the tessellation (exact_geodesics.h), searched in a band around it.
///
/// CGAL's sequence tree grows over every triangle it is given, and on flat parts of a surface every
/// vertex is a pseudo-source (CGAL's relaxed pruning counts an angle sum of 2 pi as a saddle), so
/// the band's width is the cost: 2.9 s and 560 MB for a ten-sided star on a 6,661-triangle plane
/// in the heat method's band of paths 50% longer than the shortest, 0.4 s in the chord's band
/// below.
///
/// **The chord's band** for a side from a to b (3D points on the tessellation) holds the triangles
/// with a corner v with |v - a| + |v - b| <= B, found among the tessellation's vertices hashed once
/// (no solve). At every point x of a path of length L, |x - a| + |x - b| <= L (a 3D distance never
/// exceeds the distance along the surface), and a corner of x's triangle is within the longest
/// edge e of x; so the band holds every path of length at most B - 2e.
/// 1. B = (1 + s) |a - b| + 2e + 2 (mean edge), with slack s = 1% (enough for a plane, whose
///    paths are their chords, and for arcs up to about 30 degrees of a sphere). When the shortest
///    path in that band is no longer than B - 2e, it is the shortest path on the whole surface
///    (SideBand::Chord).
/// 2. Otherwise (a side that bends over a bump) the band for B = L + 2e, with L the length of the
///    path found, holds every path no longer than that one, so its shortest is the true one
///    (SideBand::Enclosing).
/// 3. When the band does not connect the ends (an arc that bulges out of it) or pinches into a
///    non-manifold, 1 and 2 again with s = 25%.
/// 4. When that band does not connect them either (a side around a fold, whose chord cuts through
///    the air), the heat method's band (heat_geodesics.h): the distances from both ends, paths at
///    most 50% longer than the shortest plus four edges for the heat distance's error, one heat
///    solve per corner (SideBand::Heat; the one case not certified).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "elastic/regions/cut_mesh.h"
#include "elastic/regions/exact_geodesics.h"

namespace elastic::regions_detail {

/// The band a side's path was found in (the file comment explains each).
enum class SideBand { Chord, Enclosing, Heat };

struct PolygonSide {
  GeodesicPath path;
  SideBand band = SideBand::Chord;
};

/// Side k runs from corners[k] to corners[(k + 1) % n]. \throws InvalidInputError when a band is
/// not an oriented 2-manifold, NumericalError when a corner is unreachable from the one before
/// (`name` in both messages).
std::vector<PolygonSide> polygon_sides(const std::vector<Eigen::Vector3d>& positions,
                                       const std::vector<Eigen::Vector3i>& triangles,
                                       const std::vector<MeshLocation>& corners,
                                       const std::string& name);

}  // namespace elastic::regions_detail
