#pragma once
/// \file
/// Guessing which way is up for a mesh, so that previews of a y-up model (most scanned and exported
/// models: spot, bob, the Stanford bunny) are not drawn lying on their side, and z-up models (CAD,
/// the procedural shapes) are not either.
///
/// The guess looks for the side the model *stands on*: for each of the six signed axes it takes the
/// vertices within `base_slab` of the box's extreme on the opposite side (the lowest ones if that
/// axis were up), and measures the area of their 2D convex hull over the box's cross-section
/// (1 = the model rests on a face as large as its box, 0 = on a point). A cow's four hooves, a
/// vase's foot or a bust's cut span much of the cross-section; a sphere's bottom, a cow's side or
/// nose only a small patch. Rules, in order:
///   1. a box flat along one axis (extent below `flat_ratio` of the largest): that axis, +;
///   2. the axis with the largest footprint, when it is at least `min_footprint`; if the opposite
///      end of the same axis has a footprint almost as large (within `symmetric_ratio`, a
///      cylinder, a torus) the + direction is taken;
///   3. otherwise (no base: a sphere, a blob) +z.
/// The result says which rule decided, so a user can overrule it (`--up` in the tool).

#include <Eigen/Core>
#include <string>
#include <vector>

namespace elastic {

struct UpAxisOptions {
  double base_slab = 0.03;   ///< slab above the lowest point, fraction of the box extent
  double flat_ratio = 1e-3;  ///< extent below this fraction of the largest: flat
  /// Smallest footprint (fraction of the cross-section) to trust: a sphere's lowest 3% is a disc
  /// of 9% of its box's cross-section (radius^2 = 2h - h^2 with h = 0.06 of a unit radius), and a
  /// base should stand out from that.
  double min_footprint = 0.12;
  double symmetric_ratio = 0.8;  ///< opposite ends within this ratio: symmetric, take +
};

struct UpAxisGuess {
  int axis = 2;                                          ///< 0, 1, 2 for x, y, z
  int sign = 1;                                          ///< +1 or -1
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  ///< sign * e_axis
  /// Footprint of each signed axis as up: [+x, -x, +y, -y, +z, -z], fractions in [0, 1].
  std::vector<double> footprints;
  std::string reason;  ///< how the guess was made, one phrase ("the model stands on its lowest y")
  /// "+x", "-y", ...
  std::string name() const;
};

/// Guesses the up axis of a point set (a mesh's vertices). Deterministic; O(n log n).
/// \throws InvalidInputError ("up axis") for no points or a non-finite point.
UpAxisGuess guess_up_axis(const std::vector<Eigen::Vector3d>& points,
                          const UpAxisOptions& options = {});

/// Parses "x", "y", "z", "+x", "-y", ... or "X,Y,Z" (a non-zero direction) into a unit vector.
/// \throws InvalidInputError naming `name` (e.g. "--up") otherwise.
Eigen::Vector3d parse_up_direction(const std::string& text, const std::string& name);

}  // namespace elastic
