#pragma once
// The factory of each scheme, one per file of solver/lib/integrators/ (registry.cpp lists them by name).
#include <memory>

#include "integrators/integrators.hpp"

namespace enamel {

/// `paper` (newmark.cpp): Newmark beta = 0, consistent mass, H = M + dt/2 C factorised.
std::unique_ptr<Integrator> makePaperIntegrator(const CaseParams& p, const Model& m, const Materials& mat,
                                                const Operators& ops);
/// `lumped` (lumped.cpp): central differences with a diagonal mass.
std::unique_ptr<Integrator> makeLumpedIntegrator(const CaseParams& p, const Model& m, const Materials& mat,
                                                 const Operators& ops);

}  // namespace enamel
