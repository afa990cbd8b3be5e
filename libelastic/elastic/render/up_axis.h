#pragma once
/// \file
/// Guessing which way is up for a mesh, so that previews of a y-up model (most scanned and exported
/// models: spot, bob, the Stanford bunny) are not drawn lying on their side, and z-up models (CAD,
/// the procedural shapes) are not either. The guess says how sure it is: some models carry no
/// evidence of their up in their shape (a bust whose neck is narrower than its crown, a sphere),
/// and then the common convention (+y: glTF's rule, most OBJ exporters, the Stanford scans)
/// decides.
///
/// Evidence, per signed axis d (d up, so the model's *base* is its end along -d):
///   - footprint: the vertices within `base_slab` of that end, the area of their 2D convex hull
///     over the box's cross-section (1 = the model rests on a face as large as its box, 0 = on a
///     point): a cow's four hooves, a vase's foot, a bust's cut span much of the cross-section; a
///     sphere's bottom, a cow's side or nose only a small patch.
///   - open end (a mesh with faces only): a boundary loop lying within `rim_slab` of that end whose
///     hull covers at least `min_rim` of the cross-section: the cut of a scan (a hand's wrist, a
///     camel's neck), the open bottom of a pawn or a dome, the mouth of a container.
///   - flat end: the area of the faces within `base_slab` of that end that face outwards along
///     the axis within `flat_degrees`, over the cross-section (a goblet's closed foot).
///   - height field (an open mesh): the faces' vector area is at least `height_field` of their
///     area and within 30 degrees of the axis (a terrain, a dome): the surface is a graph over the
///     other two axes, and up is the side of the area centroid away from the boundary's centroid
///     (a mountain's rim is below its peak).
/// Rules, in order:
///   1. a box flat along one axis (extent below `flat_ratio` of the largest): that axis, +; high;
///   2. open ends: the largest; if the opposite end is open or flat too (a tube, a container with a
///      closed bottom) the + direction of that axis (medium), else that end is the base (high);
///   3. a height field: its axis, the side away from the boundary (high; + and medium when the two
///      centroids are level);
///   4. footprints: the largest, when it is at least `min_footprint`. If the opposite end of the
///      same axis is almost as large (within `symmetric_ratio`: a cylinder, a torus) the +
///      direction (medium). High when it stands out (at most `clear_opposite` x it at the opposite
///      end, at most 1 / `clear_ratio` of it on the other axes); otherwise low, and the convention
///      decides the sign when it is along the same axis (a bust on a narrow neck: its crown's
///      footprint is larger than its cut);
///   5. no footprint of `min_footprint` (a sphere, a blob): the convention, low.
/// The result says which rule decided and how sure it is, so a user can overrule it (`--up` in the
/// tool). A rotation of a mesh by quarter turns rotates every guess that is not decided by the
/// convention (tests/render/up_axis_test.cpp checks it on the shared meshes).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "elastic/mesh/polygon_mesh.h"

namespace elastic {

struct UpAxisOptions {
  double base_slab = 0.03;   ///< slab above the lowest point, fraction of the box extent
  double flat_ratio = 1e-3;  ///< extent below this fraction of the largest: flat
  /// Smallest footprint (fraction of the cross-section) to trust: a sphere's lowest 3% is a disc
  /// of 9% of its box's cross-section (radius^2 = 2h - h^2 with h = 0.06 of a unit radius), and a
  /// base should stand out from that.
  double min_footprint = 0.12;
  double symmetric_ratio = 0.8;  ///< opposite ends within this ratio: symmetric, take +
  /// A footprint stands out (high confidence) when the opposite end's is at most this fraction
  /// of it ...
  double clear_opposite = 0.3;
  /// ... and it is at least this many times each footprint along the other two axes.
  double clear_ratio = 2.0;
  double rim_slab = 0.1;  ///< a boundary loop within this fraction of the extent of an end is there
  double min_rim = 0.05;  ///< smallest open end (hull over the cross-section) that counts
  double flat_degrees = 10.0;  ///< faces within this angle of the axis are flat (flat ends)
  double min_flat = 0.05;      ///< smallest flat end (area over the cross-section) that counts
  /// Smallest |vector area| / area of an open mesh that makes it a height field.
  double height_field = 0.6;
  /// The up the convention gives, used where the shape does not decide (a unit signed axis).
  Eigen::Vector3d convention = Eigen::Vector3d::UnitY();
};

/// How sure a guess is: High when the shape decides by a clear margin, Medium when it decides the
/// axis but not its sign (the + direction is taken: both ends alike), Low when the convention or a
/// small margin decided.
enum class UpAxisConfidence { High, Medium, Low };

/// "high", "medium", "low".
const char* to_string(UpAxisConfidence confidence);

struct UpAxisGuess {
  int axis = 2;                                          ///< 0, 1, 2 for x, y, z
  int sign = 1;                                          ///< +1 or -1
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  ///< sign * e_axis
  /// Footprint of each signed axis as up: [+x, -x, +y, -y, +z, -z], fractions in [0, 1].
  std::vector<double> footprints;
  /// Open ends of each signed axis as up (same order; 0 without faces or boundary).
  std::vector<double> open_ends;
  /// Flat ends of each signed axis as up (same order; 0 without faces).
  std::vector<double> flat_ends;
  UpAxisConfidence confidence = UpAxisConfidence::Low;
  std::string reason;  ///< how the guess was made, one phrase ("the model stands on its lowest y")
  /// "+x", "-y", ...
  std::string name() const;
};

/// Guesses the up axis of a point set (a mesh's vertices) from its footprints only (rules 1, 4 and
/// 5). Deterministic; O(n log n).
/// \throws InvalidInputError ("up axis") for no points or a non-finite point.
UpAxisGuess guess_up_axis(const std::vector<Eigen::Vector3d>& points,
                          const UpAxisOptions& options = {});

/// Guesses the up axis of a mesh with every rule (its faces give the open and flat ends and the
/// height field). Deterministic; O(n log n) in the corners.
/// \throws InvalidInputError ("up axis") for a mesh without vertices or with a non-finite one.
UpAxisGuess guess_up_axis(const PolygonMesh& mesh, const UpAxisOptions& options = {});

/// Parses "x", "y", "z", "+x", "-y", ... or "X,Y,Z" (a non-zero direction) into a unit vector.
/// \throws InvalidInputError naming `name` (e.g. "--up") otherwise.
Eigen::Vector3d parse_up_direction(const std::string& text, const std::string& name);

}  // namespace elastic
