#pragma once
/// \file
/// The energies of the particle system on the target surface (paper §4.2, §4.4 and the Appendix)
/// and their exact gradients, plus the rest-scale factor and the fold test the solvers use.
///
/// With x_i the 3D target position of particle i (3 x #P matrix `x`), sigma the rest scale:
///
/// - normal springs (eq. 13, Appendix):
///       E_len = C * sum_{springs (i,j)} (|x_j - x_i| - sigma k_ij)^2
///   gradient on j: 2C (|d| - sigma k) d/|d| with d = x_j - x_i, and its negative on i. The paper's
///   eq. 14 writes this force as C d/|d| (|d| - k): its C is our 2C (eq. 13 sums every spring
///   twice, once from each end, we sum it once).
/// - angular springs (§4.1, Fig. 1):
///       E_ang = C_a * sum_{corners (i; a, b)} (|x_i - (x_a + x_b)/2| - sigma r_i)^2
///   gradient on i: g = 2C_a (|e| - sigma r) e/|e| with e = x_i - (x_a + x_b)/2; on a and on b
///   exactly -g/2 (the virtual midpoint moves by half of what a or b moves). These are the paper's
///   "opposite force with half the magnitude" on the two neighbours, and the three sum to zero: the
///   springs conserve momentum.
/// - magnet (§4.4, Appendix):
///       E_mag = c/2 * sum_i |x_i - x'_i|^2,   x'_i the closest point of the surface to x_i.
///   Half the squared distance to a smooth surface has gradient x - x' (the closest point moves,
///   but only along the surface, orthogonally to x - x': envelope theorem), so the gradient is
///   c (x - x'), the paper's force f^m = c (x' - x). The paper writes the energy without the 1/2;
///   we keep its force.
///
/// - injectivity barrier (beyond the paper; SpringEnergyOptions::barrier_stiffness > 0):
///       E_bar = mu * sum_{triangles t} w_t sigma^2 A_t * h(g_t),
///       h(g) = (g / g0 - 1)^3 for g > g0, else 0
///   over every triangle of both triangulations of each quad (weight w = 1/2, so each split covers
///   the quad once) and every triangle face (w = 1); A_t is the source area (sigma^2 A_t the rest
///   area at the target's scale, so that E_bar, like the springs, scales with the square of the
///   target's units and the minimiser does not depend on them) and
///   g_t = s1^-2 + s2^-2 the inverse part of the symmetric Dirichlet energy of the triangle's
///   affine map divided by sigma (s1, s2 its singular values, as in metrics/map_metrics.h). In
///   Gram-matrix form, with S, T the 3 x 2 edge matrices of the source and target triangle:
///       g = sigma^2 tr((S^T S)^-1 T^T T) det(S^T S) / det(T^T T),
///   smooth in the target positions, infinite as the target triangle collapses (det(T^T T) -> 0;
///   given surface normals, evaluate() uses the signed area seen along the unit sum of its three
///   corners' normals instead, infinite as the triangle folds in face_folds.h's sense),
///   and zero unless the smaller stretch falls to about 1/sqrt(g0) = barrier_sigma (g0 =
///   barrier_sigma^-2): it leaves every triangle that is not close to collapse alone, so the
///   paper's minimum is unchanged wherever it is not degenerate. It is the barrier of Smith and
///   Schaefer 2015 (bijective parameterisation with free boundaries) restricted to a threshold:
///   combined with a line search that rejects inverted triangles it keeps every triangle's
///   sigma_min away from 0 (no slivers under compression), and so no triangle can fold. Triangles
///   already inverted where the barrier is switched on (set_barrier_mask) are left out of it.
///
/// - distortion term (beyond the paper; SpringEnergyOptions::distortion_stiffness > 0):
///       E_sd = lambda * sum_t w_t sigma^2 A_t * (s1^2 + s2^2 + s1^-2 + s2^-2 - 4)
///   over the barrier's triangles: the symmetric Dirichlet energy of each triangle's affine map
///   divided by sigma (metrics/map_metrics.h), zero for an isometry at the rest scale. In the
///   Gram form above, s1^2 + s2^2 = tr((S^T S)^-1 T^T T) / sigma^2 and s1^-2 + s2^-2 = g. The
///   springs see lengths along grid edges only; this term also sees shear, which a quad grid's
///   springs let through cheaply (on a hump, a length-preserving map trades angles for lengths).
///   It is itself infinite at collapse, and it leaves the barrier's triangles out in the same way.
///
/// Degenerate springs: at |d| = 0 (or |e| = 0) the energy has a cone point and no gradient; that
/// spring then contributes zero to the gradient (a valid subgradient choice that keeps the sum of
/// forces zero).
///
/// Threads and determinism: the gradient is computed per spring into a buffer (in parallel), then
/// gathered per particle in a fixed order (in parallel); energies are summed with a deterministic
/// reduction. The result is bit-identical for the same input whatever the number of threads.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <string_view>
#include <vector>

#include "elastic/particles/particle_grid.h"

namespace elastic {

/// How the rest lengths are scaled when the source and target regions differ in size.
enum class RestScale {
  /// sigma = min(Boundary, Area): the largest scale that compresses neither the boundary nor the
  /// region as a whole (the default). A grid whose rest lengths do not fit the target buckles:
  /// with the boundary held, a target region smaller than sigma^2 times the source's area can
  /// only take the excess by slivers or folds, while stretch is spread smoothly. Whichever of the
  /// two ratios is smaller is the one that fits.
  Auto,
  Boundary,  ///< sigma = target boundary length / source boundary length (the paper's Table 1)
  Area,      ///< sigma = sqrt(target area / source area)
  None       ///< sigma = 1: absolute sizes are kept
};

/// "auto", "boundary", "area", "none".
std::string_view to_string(RestScale mode);
/// Parses "auto", "boundary", "area", "none". \throws InvalidInputError naming `input` otherwise.
RestScale parse_rest_scale(std::string_view text, std::string_view input = "rest scale");

/// Sizes of the two regions that the rest-scale factor compares.
struct RegionSizes {
  double source_boundary_length = 1.0;  ///< length of the source boundary curve
  double target_boundary_length = 1.0;  ///< length of the target boundary curve
  double source_area = 1.0;             ///< area of the source region
  double target_area = 1.0;             ///< area of the target region
};

/// The factor sigma of the chosen mode (see RestScale).
/// \throws InvalidInputError when a size the mode uses is not finite and positive.
double rest_scale_factor(RestScale mode, const RegionSizes& sizes);

/// The default threshold of the injectivity barrier (SpringEnergyOptions::barrier_sigma): 0.42
/// keeps the robustness benchmark's sharpest tips (a 36-degree star tip opened to about 180) at
/// sigma_min >= 0.2 (0.209 onto spot's flank; 0.192 at 0.4) at a length energy still below 0.9 of
/// the best baseline's in every case (docs/solvers.md).
inline constexpr double kDefaultBarrierSigma = 0.42;

struct SpringEnergyOptions {
  double stiffness = 1.0;          ///< C, normal springs (eq. 13)
  double angular_stiffness = 1.0;  ///< C_a, angular springs
  double rest_scale = 1.0;         ///< sigma, multiplies every rest value
  /// mu of the injectivity barrier E_bar (see the file comment), relative to C: the barrier's
  /// weight is mu * C. 0: off, the paper's energy E_len + E_ang alone.
  double barrier_stiffness = 0.0;
  /// The smaller stretch (divided by sigma) below which the barrier starts to act, about; in
  /// (0, 1).
  double barrier_sigma = kDefaultBarrierSigma;
  /// lambda of the distortion term E_sd (see the file comment), relative to C: its weight is
  /// lambda * C. 0: off. It trades length for angle fidelity (docs/solvers.md).
  double distortion_stiffness = 0.0;

  /// Whether the terms over grid triangles (E_bar, E_sd) are on.
  bool triangle_terms() const { return barrier_stiffness > 0.0 || distortion_stiffness > 0.0; }
};

/// Energies per term.
struct SpringEnergies {
  double length = 0.0;      ///< E_len (eq. 13)
  double angular = 0.0;     ///< E_ang
  double barrier = 0.0;     ///< E_bar (0 when the barrier is off)
  double distortion = 0.0;  ///< E_sd (0 when it is off)
  double total() const { return length + angular + barrier + distortion; }
};

/// The spring energies of one ParticleGrid, with the incidence tables precomputed for fast,
/// deterministic evaluation. The grid must outlive the object and its springs must be built.
/// `evaluate` uses internal scratch buffers: one SpringSystem must not evaluate from two threads at
/// once (it parallelises itself).
class SpringSystem {
 public:
  /// \throws InvalidInputError when the grid has no springs or a spring index is out of range,
  ///         or the options are not finite and non-negative (rest_scale positive).
  SpringSystem(const ParticleGrid& grid, const SpringEnergyOptions& options = {});

  int num_particles() const { return num_particles_; }
  const SpringEnergyOptions& options() const { return options_; }

  /// Energies at positions `x` (3 x #P); when `gradient` is given it receives dE/dx (3 x #P,
  /// resized). With `normals` (3 x #P unit surface normals at the particles) the barrier measures
  /// each triangle's area as seen along u = s / |s|, s = n_i + n_next + n_prev the sum of its
  /// corners' normals, signed: det(T^T T) becomes ((T0 x T1) . u)^2 and a triangle with
  /// (T0 x T1) . u <= 0 has infinite energy, so that the barrier guards exactly the fold test of
  /// face_folds.h, which folded_corners() and the map's report share (a thin triangle standing up
  /// from the surface has a fine 3D area but is folded as seen from it). The gradient holds the
  /// normals fixed; `normal_gradient` (with `normals` only) receives dE/dn_p, the barrier's
  /// derivative with respect to each particle's normal (3 x #P, resized; zero where p is the
  /// corner of no active barrier triangle). A solver whose normals follow the positions on a
  /// surface (n_p = n(x_p)) adds dn/dx_p^T dE/dn_p to the gradient
  /// (LimitSurface::normal_variation_adjoint) and so differentiates the energy it evaluates.
  /// Without normals: the unsigned 3D area.
  SpringEnergies evaluate(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd* gradient = nullptr,
                          const Eigen::Matrix3Xd* normals = nullptr,
                          Eigen::Matrix3Xd* normal_gradient = nullptr) const;

  /// The normal and angular springs alone (E_len and E_ang; the triangle terms left out) and,
  /// when `gradient` is given, their gradient: what evaluate() of a system with barrier and
  /// distortion stiffness 0 gives, without a second system's memory (280 MB at a million
  /// particles).
  SpringEnergies evaluate_springs(const Eigen::Matrix3Xd& x,
                                  Eigen::Matrix3Xd* gradient = nullptr) const;

  /// The Hessian of evaluate()'s energy at `x` in reduced coordinates: K = B^T H B, B the
  /// block-diagonal basis of `basis` (particle p's motion is B_p z_p). With `normals` the barrier
  /// sees each triangle along its corners' normals as in evaluate(), the normals held fixed (their
  /// turning is left out); without them along the unit normal of the triangle itself. With
  /// `project`, each term's Hessian has its negative eigenvalues set to zero (projected Newton,
  /// Teran et al. 2005), so K is positive semi-definite: a spring's part along its
  /// direction 2C n n^T is kept and the part across it, 2C (1 - sigma k / |d|) (I - n n^T),
  /// dropped where the spring is compressed; a triangle's 6 x 6 Hessian in its edges is clamped
  /// in its eigenbasis. Terms with a degenerate spring (|d| = 0), an inactive barrier triangle,
  /// or one whose energy is infinite at `x` are left out. Returns the lower and upper triangle
  /// (size basis.size() squared). Same entries for any number of threads.
  struct HessianBasis {
    std::vector<int> first;    ///< #P: the first reduced coordinate of particle p
    std::vector<int> count;    ///< #P: how many (0 to 3); 0 for a particle that does not move
    Eigen::Matrix3Xd vectors;  ///< 3 x size(): the basis vector of each reduced coordinate
    Eigen::Index size() const { return vectors.cols(); }
  };
  Eigen::SparseMatrix<double> hessian(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd* normals,
                                      const HessianBasis& basis, bool project = true) const;

  /// Number of grid faces with at least one folded corner at positions `x`, given unit surface
  /// normals `normals` (3 x #P) at the particles. A corner (prev, i, next) of a counter-clockwise
  /// face is folded when its triangle is inverted in the sense of face_folds.h:
  /// ((x_next - x_i) x (x_prev - x_i)) . (n_i + n_next + n_prev) <= 0. For triangles and quads
  /// (whose four corners are the four triangles of its two splits) this is inverted_faces().
  int folded_faces(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& normals) const;
  /// Per corner (in the order of `corners()`), whether it is folded.
  void folded_corners(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& normals,
                      std::vector<char>& folded) const;

  /// Leaves out of the barrier every barrier triangle that is inverted at `x` (normals: 3 x #P unit
  /// surface normals, the fold test of folded_corners) and puts every other
  /// one in. Returns the number left out. Without a call every triangle is in.
  int set_barrier_mask(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& normals);
  /// Number of barrier triangles (both splits of each quad and every triangle face).
  int num_barrier_triangles() const { return static_cast<int>(barrier_.size()); }

  /// A face corner for the fold test: particle i and its successor and predecessor in the face.
  struct Corner {
    int i = -1;
    int next = -1;
    int prev = -1;
    int face = -1;
  };
  const std::vector<Corner>& corners() const { return corners_; }

 private:
  void build_barrier(const ParticleGrid& grid);
  // Throws InvalidInputError unless x has a column per particle.
  void check_positions(const Eigen::Matrix3Xd& x) const;
  // The three terms of evaluate(), each filling its force buffer when want_gradient, and the
  // gather of those forces into the gradient.
  double length_energy(const Eigen::Matrix3Xd& x, bool want_gradient) const;
  double angular_energy(const Eigen::Matrix3Xd& x, bool want_gradient) const;
  // One barrier triangle's terms (spring_energy.cpp).
  struct TriangleTerms {
    double barrier = 0.0, distortion = 0.0;
    bool has_gradient = false;  // a non-zero dE/da or dE/dD
    Eigen::Vector3d f0 = Eigen::Vector3d::Zero(), f1 = Eigen::Vector3d::Zero();  // next, prev
    Eigen::Vector3d fn = Eigen::Vector3d::Zero();  // dE/dn of each corner
  };
  TriangleTerms triangle_terms(std::size_t t, const Eigen::Matrix3Xd& x,
                               const Eigen::Matrix3Xd* normals, bool gradient) const;
  Eigen::Vector2d triangle_energy(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd* normals,
                                  bool want_gradient) const;
  void gather_gradient(bool with_barrier, Eigen::Matrix3Xd& gradient) const;
  void gather_normal_gradient(Eigen::Matrix3Xd& normal_gradient) const;
  // The 9 x 9 Hessian of barrier triangle t's terms in (x_i, x_next, x_prev) (spring_hessian.cpp);
  // false when it has none (inactive, infinite energy, or every term zero).
  bool triangle_hessian(std::size_t t, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd* normals,
                        bool project, Eigen::Matrix<double, 9, 9>& h) const;

  const ParticleGrid* grid_ = nullptr;
  SpringEnergyOptions options_;
  int num_particles_ = 0;
  // Incidence in compressed rows: for particle p, entries [offset[p], offset[p+1]) encode 2*index +
  // side (side 0: p is the spring's j / the corner's i, side 1: p is i / one of a, b).
  std::vector<int> spring_offset_, spring_entry_;
  std::vector<int> angular_offset_, angular_entry_;
  std::vector<Corner> corners_;
  // One triangle of the barrier: apex i, then next and prev in the face's order
  // (counter-clockwise), the weight w A_s, and the source metric: B = (S^T S)^-1 (b00, b01, b11)
  // and det(S^T S).
  struct BarrierTriangle {
    int i = -1, next = -1, prev = -1;
    double weight = 0.0;
    double b00 = 0.0, b01 = 0.0, b11 = 0.0;
    double source_det = 0.0;
  };
  std::vector<BarrierTriangle> barrier_;
  std::vector<char> barrier_active_;
  std::vector<int> barrier_offset_,
      barrier_entry_;  // code 3 * triangle + role (0 i, 1 next, 2 prev)
  // The last evaluation's barrier forces, for the triangles that had any: barrier_slot_[t] is
  // triangle t's slot (-1: none); 2 columns per slot, dE/dx of next and prev (that of i is minus
  // their sum), and dE/dn of its corners (with normals).
  mutable std::vector<int> barrier_slot_;
  mutable Eigen::Matrix3Xd barrier_force_;
  mutable Eigen::Matrix3Xd barrier_normal_force_;
  mutable Eigen::Matrix3Xd spring_force_;   // per spring: dE/dx_j
  mutable Eigen::Matrix3Xd angular_force_;  // per angular spring: dE/dx_i
};

/// Convenience: builds a SpringSystem and evaluates it once.
SpringEnergies spring_energy(const ParticleGrid& grid, const Eigen::Matrix3Xd& x,
                             const SpringEnergyOptions& options = {},
                             Eigen::Matrix3Xd* gradient = nullptr);

/// The magnet energy (§4.4) c/2 * sum_i |x_i - x'_i|^2 over the particles with `active[i]` != 0
/// (all when `active` is empty), x' the closest surface points (3 x #P). When `gradient` is given,
/// c (x - x') is *added* to it for the active particles (it must be 3 x #P).
double magnet_energy(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& closest, double stiffness,
                     const std::vector<char>& active = {}, Eigen::Matrix3Xd* gradient = nullptr);

}  // namespace elastic
