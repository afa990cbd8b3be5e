#pragma once
/// \file
/// Faithful mode of `relax` (relaxation.h): the paper's damped particle dynamics (§4.5, eq. 9)
///     m x'' + gamma x' + grad E(x) = 0,   E = E_len + E_ang + E_mag,
/// integrated with the explicit scheme of §4.6 (eqs. 10-12), per interior particle and step:
///     a = f / m,   v += a dt,   x += v dt,    f = -grad(E_len + E_ang) - c (x - x') - gamma v,
/// where x' is the closest point of the target surface (the magnet, §4.4, warm started from the
/// particle's last surface point). Boundary particles never move.
///
/// Stable defaults (ExplicitOptions fields left at 0):
/// - time step: the update is symplectic Euler, stable for a mode of stiffness lambda while
///   dt < 2 sqrt(m / lambda). The largest stiffness lambda_max is bounded (Gershgorin) by the
///   largest absolute row sum of the interior spring Laplacian L (2C per spring, the angular Gram
///   matrices; a spring's Hessian norm never exceeds 2C unless it is compressed below half its rest
///   length) plus the magnet stiffness c. The default is
///   dt = stability_factor * 2 sqrt(m / lambda_max), stability_factor 0.5.
/// - magnet stiffness: c = the largest diagonal entry of L, so pulling a particle back onto the
///   surface is as stiff as the stiffest particle's springs (its mode is covered by the time step).
/// - damping: the slowest in-plane mode has stiffness about lambda_min(L) / 2 (a spring's Hessian
///   2C d d^T averages to C I over directions in the plane); gamma = 2 sqrt(m lambda_min(L) / 2)
///   damps it critically, the fastest decay of the slowest error. lambda_min(L) comes from 30 steps
///   of inverse iteration with the factorised L (set-up time).
///
/// Drift: the magnet balances the springs' normal pull only up to an offset f_n / c; when a
/// particle drifts farther than drift_tolerance * mean rest length from the surface, all interior
/// particles are placed exactly on their closest points and lose the normal component of their
/// velocity (counted in RelaxationResult::reprojections).
///
/// Equilibrium: every 10 steps the tangential gradient is evaluated at the projected positions x';
/// the run stops with the criterion of relaxation.h and returns those projected positions. The
/// progress callback is called at these checks; the frame callback every frame_interval steps with
/// the integrator state x.

#include "elastic/solvers/relaxation.h"

namespace elastic {

/// Runs the explicit integrator (use `relax` with SolverKind::Faithful; this is what it calls).
/// \throws as relax; InvalidInputError when ExplicitOptions are negative or not finite.
RelaxationResult relax_explicit(const RelaxationProblem& problem, const RelaxationOptions& options);

}  // namespace elastic
