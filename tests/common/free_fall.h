#pragma once
/// The analytic free fall the solvers are tested against.
#include <cmath>

#include "core/params.h"

namespace tender::test {

/// How far a free particle falls in `ticks` ticks of damped Verlet from rest: the displacement
/// of substep n is D_n = g dt^2 (1 - d^n) / (1 - d), and the drop sums them.
inline double dampedVerletDrop(const SimParams& p, int ticks) {
  const double g = p.gravity, dt = 1.0 / (double(p.tick_hz) * p.substeps), d = p.damping;
  const double n = double(ticks) * p.substeps;
  return g * dt * dt / (1.0 - d) * (n - d * (1.0 - std::pow(d, n)) / (1.0 - d));
}

} // namespace tender::test
