#pragma once
/// \file
/// Fast mode of `relax` (relaxation.h): a tangent-space quasi-Newton solver for min E_len + E_ang
/// over the interior particles constrained to the target limit surface. Not in the paper; it
/// reaches the equilibrium the paper's integrator (eqs. 9-12) converges to, in far fewer
/// evaluations.
///
/// Per iteration, with g the spring gradient (3 x #P) and P the projection on the tangent planes at
/// the interior particles (boundary rows are zero: those particles are fixed):
/// 1. Tangential gradient q = P g (the force the magnet leaves once particles sit on the surface).
/// 2. Direction p = -H q by the L-BFGS two-loop recursion over the last `memory` pairs (s, y)
///    (s: change of the positions, y: change of P g), with the initial inverse Hessian H0 = L^-1,
///    L the interior spring Laplacian (spring_laplacian.h: 2C per spring plus the angular springs'
///    Gram matrices), applied to the x, y and z coordinates by one algebraic-multigrid V-cycle
///    (multigrid.h, default) or an exact sparse LDL^T in nested-dissection order
///    (LbfgsOptions::preconditioner). The first step is therefore (about) the Laplacian solve
///    -L^-1 P g, a Newton step for the springs linearised at rest. After that H0 = gamma L^-1,
///    gamma = s.y / (y.L^-1 y) of the newest pair (LbfgsOptions::scale_h0: not in the slide of a
///    sliding boundary, nor while the barrier's energy is above the springs').
/// 3. p is projected on the tangent planes again. If it is not a descent direction (P g . p >= 0)
///    the memory is cleared and p = -P L^-1 P g is used.
/// 4. Retraction: the tangent step t_i = alpha p_i is pulled back to the parameter plane of the
///    particle's ptex face, delta = (J^T J)^-1 J^T t with J = [du dv], corrected to second order
///    by the surface's second derivatives, walked across ptex edges, and evaluated: one patch
///    evaluation per particle. Like the magnet (closest point of x + t, §4.4) it moves the particle
///    by t + O(|t|^3) along the surface. A landing that misses x + t tangentially by more than
///    1e-3 |t| (after crossing an irregular ptex edge) is corrected to the foot of x + t by
///    Gauss-Newton steps; where the parameterisation is degenerate, the walk reaches the surface
///    boundary or the correction fails, the magnet itself is used (warm started). See
///    solver_detail::parametric_retraction.
/// 5. Backtracking line search from alpha = 1, or with LbfgsOptions::step_memory (the default,
///    where H0 is not scaled) from twice the fraction of its full step the previous iteration
///    accepted (at most 1; 1 after the memory is cleared or when that fraction was below 1/256).
///    A trial that folds a face corner that was not folded (SpringSystem::folded_corners with
///    the new normals) is never taken. The first 4 such trials halve alpha; after that the free
///    particles of the newly folded corners are *held*: they keep their position from then on,
///    like boundary particles, and the solver continues in the subspace of the others (their rows
///    of P g, of L^-1 and of p are zero; the memory is cleared and p recomputed as -P L^-1 P g on
///    the new subspace), retrying the same alpha, up to 8 rounds, after which alpha is halved
///    again. A trial is also rejected (alpha
///    halved) when the energy is not finite or the Armijo condition E(alpha) <= E + c1 alpha (P g .
///    p) fails. Close to the minimum the energy change can drop below its round-off; a trial within
///    the energy's round-off (max(1e-13 E, 8 eps (1 + extent / mean rest) sqrt(E sum C k^2)), which
///    falls only like sqrt(E) near a perfect map) is then accepted when its tangential gradient is
///    smaller.
/// 6. The pair (s, y) is kept when s . y > 1e-12 |s| |y| (curvature condition), stored in single
///    precision (the recursion computes in double).
///
/// 7. The Newton H0 (LbfgsOptions::newton, newton_preconditioner.h): in the default
/// NewtonMode::Auto,
///    after 50 iterations without convergence on a grid of at most 10,000 free particles (outside
///    a sliding boundary's slide phase, and while the barrier's energy is at most the springs'),
///    H0 is the energy's own Hessian in the tangent planes, K^-1, refactorised every 4 iterations,
///    instead of L^-1 (the memory is cleared when H0 changes). Where the map is far from rest,
///    compressed, or pressed against the barrier, L is a poor model and the pairs cannot make up
///    for it; K is the model itself.
///
/// Stopping: see relaxation.h (tangential gradient only). The slide phase of a sliding boundary
/// also stops when 20 iterations lowered its energy by less than
/// RelaxationOptions::slide_settle_tolerance of it (StopReason::Settled). When particles are held
/// and the tangential gradient of all the others meets the tolerance, the held ones are released
/// once (memory cleared); if they are held again and the rest settles again, the energy minimum
/// lies beyond the no-fold constraint: the solver stops with StopReason::FoldConstrained (not
/// converged, no folds, RelaxationResult::held_particles lists them). This is the case of a square
/// source region mapped onto a round target boundary with 2,000 particles: its 90-degree corners
/// must open to 180 degrees, and the explicit solver run to equilibrium folds faces next to them.
/// When no trial is accepted with an empty memory, or 20 steps in a row change the energy by less
/// than 1e-14 E, it stops with StopReason::LineSearchFailed. In any phase it stops with
/// StopReason::Stagnated (not converged) when kStagnationWindow iterations lowered the energy by
/// less than kStagnationEnergy of it and did not lower the smallest tangential gradient so far by
/// 10%.

#include "elastic/solvers/relaxation.h"

namespace elastic {

/// Runs the L-BFGS solver (`relax` with SolverKind::Fast calls it, in the caller's TBB arena).
/// \throws as relax.
RelaxationResult relax_lbfgs(const RelaxationProblem& problem, const RelaxationOptions& options);

}  // namespace elastic
